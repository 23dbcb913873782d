#pragma once
// pins Cyclone DDS's receive sockets to one address. Cyclone DDS (0.10, and its master branch:
// ddsi_udp.c) binds the UDP sockets it receives on to the wildcard address (0.0.0.0 / ::) whatever
// network interface it is configured for; only its transmit socket is bound to the interface. so
// that the ROS 2 bridge listens only where it was told, this file defines bind(2) for the process
// (it interposes on the C library's, which it calls): while a ScopedUdpBindPin lives, a UDP
// socket that the pin's thread binds to the wildcard address of the pin's address family, and
// that has no SO_REUSEADDR (Cyclone sets it only on multicast receive sockets, which must stay on
// the wildcard to receive multicast on Linux), is bound to the pinned address instead, same port.
// every other bind of the process, and any bind on another thread, is passed on unchanged.

#include <string>

namespace penumbra {

/// pins wildcard UDP binds of this thread to `numeric_address` (IPv4 or IPv6) while alive.
/// @throws Error when `numeric_address` is not numeric, or when the C library's bind cannot be
///         found (the pin would do nothing).
class ScopedUdpBindPin {
 public:
  explicit ScopedUdpBindPin(const std::string& numeric_address);
  ~ScopedUdpBindPin();
  ScopedUdpBindPin(const ScopedUdpBindPin&) = delete;
  ScopedUdpBindPin& operator=(const ScopedUdpBindPin&) = delete;

  /// wildcard binds that were pinned while this pin lived.
  int pinned() const;

 private:
  int previous_pinned_ = 0;
};

}  // namespace penumbra
