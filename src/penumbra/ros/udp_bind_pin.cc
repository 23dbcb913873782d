#include "penumbra/ros/udp_bind_pin.h"

#include <arpa/inet.h>
#include <dlfcn.h>
#include <netinet/in.h>
#include <sys/socket.h>

#include <cerrno>
#include <cstring>

#include "penumbra/core/error.h"

namespace {

using BindFn = int (*)(int, const sockaddr*, socklen_t);

BindFn RealBind() {
  static const BindFn real = reinterpret_cast<BindFn>(dlsym(RTLD_NEXT, "bind"));
  return real;
}

// the pinned address of this thread (family 0: none) and the binds pinned so far
thread_local sockaddr_storage tls_pin{};
thread_local int tls_pinned = 0;

// whether `fd` is a UDP socket without SO_REUSEADDR
bool PlainUdp(int fd) {
  int type = 0, reuse = 0;
  socklen_t len = sizeof type;
  if (getsockopt(fd, SOL_SOCKET, SO_TYPE, &type, &len) != 0 || type != SOCK_DGRAM) return false;
  len = sizeof reuse;
  return getsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &reuse, &len) == 0 && reuse == 0;
}

}  // namespace

// the process's bind(2): see udp_bind_pin.h
extern "C" int bind(int fd, const sockaddr* addr, socklen_t len) {
  const BindFn real = RealBind();
  if (!real) {
    errno = ENOSYS;
    return -1;
  }
  if (tls_pin.ss_family == 0 || !addr || addr->sa_family != tls_pin.ss_family)
    return real(fd, addr, len);
  if (addr->sa_family == AF_INET && len >= static_cast<socklen_t>(sizeof(sockaddr_in))) {
    sockaddr_in a;
    std::memcpy(&a, addr, sizeof a);
    if (a.sin_addr.s_addr != htonl(INADDR_ANY) || !PlainUdp(fd)) return real(fd, addr, len);
    a.sin_addr = reinterpret_cast<const sockaddr_in*>(&tls_pin)->sin_addr;
    ++tls_pinned;
    return real(fd, reinterpret_cast<const sockaddr*>(&a), sizeof a);
  }
  if (addr->sa_family == AF_INET6 && len >= static_cast<socklen_t>(sizeof(sockaddr_in6))) {
    sockaddr_in6 a;
    std::memcpy(&a, addr, sizeof a);
    if (std::memcmp(&a.sin6_addr, &in6addr_any, sizeof a.sin6_addr) != 0 || !PlainUdp(fd))
      return real(fd, addr, len);
    a.sin6_addr = reinterpret_cast<const sockaddr_in6*>(&tls_pin)->sin6_addr;
    ++tls_pinned;
    return real(fd, reinterpret_cast<const sockaddr*>(&a), sizeof a);
  }
  return real(fd, addr, len);
}

namespace penumbra {

ScopedUdpBindPin::ScopedUdpBindPin(const std::string& numeric_address) {
  if (!RealBind()) throw Error("cannot find the C library's bind(2) (dlsym)");
  sockaddr_storage pin{};
  auto* a4 = reinterpret_cast<sockaddr_in*>(&pin);
  auto* a6 = reinterpret_cast<sockaddr_in6*>(&pin);
  if (inet_pton(AF_INET, numeric_address.c_str(), &a4->sin_addr) == 1)
    pin.ss_family = AF_INET;
  else if (inet_pton(AF_INET6, numeric_address.c_str(), &a6->sin6_addr) == 1)
    pin.ss_family = AF_INET6;
  else
    throw Error("'" + numeric_address + "' is not a numeric IPv4 or IPv6 address");
  tls_pin = pin;
  previous_pinned_ = tls_pinned;
}

ScopedUdpBindPin::~ScopedUdpBindPin() { tls_pin = sockaddr_storage{}; }

int ScopedUdpBindPin::pinned() const { return tls_pinned - previous_pinned_; }

}  // namespace penumbra
