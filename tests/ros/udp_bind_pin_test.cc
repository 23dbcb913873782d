// ScopedUdpBindPin (ros/udp_bind_pin.h): wildcard UDP binds of the pinning thread go to the
// pinned address, every other bind is left alone; and a ROS 2 node's Cyclone DDS sockets listen
// on its interface only (checked in /proc/net/udp, as `ss -uan` shows them).
#include "penumbra/ros/udp_bind_pin.h"

#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "penumbra/core/error.h"
#include "penumbra/ros/ros2/ros2_node.h"
#include "penumbra/ros/ros2/ros2_types.h"

namespace penumbra {
namespace {

// binds a new socket of `type` to 0.0.0.0:0 (with SO_REUSEADDR when asked) and returns the
// address it got ("" when bind failed)
std::string BindWildcard(int type, bool reuse = false) {
  const int fd = socket(AF_INET, type, 0);
  if (fd < 0) return "";
  const int one = 1;
  if (reuse) setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_addr.s_addr = htonl(INADDR_ANY);
  std::string got;
  if (bind(fd, reinterpret_cast<const sockaddr*>(&a), sizeof a) == 0) {
    sockaddr_in b{};
    socklen_t len = sizeof b;
    getsockname(fd, reinterpret_cast<sockaddr*>(&b), &len);
    char text[INET_ADDRSTRLEN] = {};
    inet_ntop(AF_INET, &b.sin_addr, text, sizeof text);
    got = text;
  }
  close(fd);
  return got;
}

TEST(UdpBindPin, PinsWildcardUdpBindsOfItsThreadOnly) {
  EXPECT_EQ(BindWildcard(SOCK_DGRAM), "0.0.0.0");
  {
    const ScopedUdpBindPin pin("127.0.0.1");
    EXPECT_EQ(BindWildcard(SOCK_DGRAM), "127.0.0.1");
    // a multicast receive socket (SO_REUSEADDR) and TCP sockets keep the wildcard
    EXPECT_EQ(BindWildcard(SOCK_DGRAM, true), "0.0.0.0");
    EXPECT_EQ(BindWildcard(SOCK_STREAM), "0.0.0.0");
    std::string other;
    std::thread([&] { other = BindWildcard(SOCK_DGRAM); }).join();
    EXPECT_EQ(other, "0.0.0.0");
    EXPECT_EQ(pin.pinned(), 1);
  }
  EXPECT_EQ(BindWildcard(SOCK_DGRAM), "0.0.0.0");
  EXPECT_THROW(ScopedUdpBindPin("localhost"), Error);
}

// the local addresses (hex "0100007F:XXXX" as /proc/net/udp writes them) bound to `port`
std::vector<std::string> UdpAddressesOnPort(int port) {
  std::ifstream in("/proc/net/udp");
  std::string line;
  std::getline(in, line);
  std::vector<std::string> found;
  char hex[8];
  std::snprintf(hex, sizeof hex, "%04X", port);
  while (std::getline(in, line)) {
    std::istringstream words(line);
    std::string slot, local;
    words >> slot >> local;
    if (local.size() > 5 && local.substr(local.size() - 4) == hex) found.push_back(local);
  }
  return found;
}

TEST(UdpBindPin, Ros2NodeListensOnItsInterfaceOnly) {
  if (!Ros2Available()) GTEST_SKIP() << "this build has no ROS 2";
  Ros2Node::Options o;
  o.domain_id = 227;
  o.interface_address = "127.0.0.1";
  Ros2Node node(o);
  // DDS-RTPS ports of the domain: discovery 7400 + 250 d + 10 + 2 i, user data + 1
  bool any = false;
  for (int pidx = 0; pidx < 32; ++pidx)
    for (int port : {7400 + 250 * 227 + 10 + 2 * pidx, 7400 + 250 * 227 + 11 + 2 * pidx})
      for (const std::string& local : UdpAddressesOnPort(port)) {
        // a port another process took is not ours: only a wildcard bind would be wrong, and
        // no process of this test binds these ports to the wildcard
        EXPECT_EQ(local.substr(0, 8), "0100007F") << "port " << port << " bound to " << local;
        any = true;
      }
  EXPECT_TRUE(any) << "no socket of the node found in /proc/net/udp";
}

}  // namespace
}  // namespace penumbra
