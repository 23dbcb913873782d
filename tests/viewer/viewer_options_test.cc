#include <gtest/gtest.h>

#include "penumbra/core/error.h"
#include "penumbra/viewer/viewer_bridge.h"

namespace penumbra {
namespace {

TEST(ViewerOptionsTest, ParsesAddresses) {
  ViewerOptions o;
  ParseViewerAddress("", &o);
  EXPECT_EQ(o.host, "127.0.0.1");
  EXPECT_EQ(o.port, 8080);
  ParseViewerAddress("9000", &o);
  EXPECT_EQ(o.port, 9000);
  EXPECT_EQ(o.host, "127.0.0.1");
  ParseViewerAddress(":0", &o);
  EXPECT_EQ(o.port, 0);
  ParseViewerAddress("0.0.0.0:8081", &o);
  EXPECT_EQ(o.host, "0.0.0.0");
  EXPECT_EQ(o.port, 8081);
  ParseViewerAddress("[::1]:8082", &o);
  EXPECT_EQ(o.host, "::1");
  EXPECT_EQ(o.port, 8082);
  for (const char* bad :
       {"host:", "host:http", "1.2.3.4:65536", "-1", "[::1]8080", "[::1", "a:1x"}) {
    ViewerOptions p;
    try {
      ParseViewerAddress(bad, &p);
      ADD_FAILURE() << "accepted " << bad;
    } catch (const ConfigError& e) {
      EXPECT_EQ(e.key(), "--viewer") << bad;
    }
  }
  ViewerOptions q;
  q.state_hz = 0;
  EXPECT_THROW(q.ValidateOrThrow(), ConfigError);
}

}  // namespace
}  // namespace penumbra
