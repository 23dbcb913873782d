// a LiDAR pattern never grows past kMaxLidarBeamsPerScan. columns: 1e9 used to
// end in a bare std::bad_alloc, and a tiny rate_hz made the presets' default column count
// (beams per second / rate) overflow an int.

#include <gtest/gtest.h>

#include <string>

#include "penumbra/core/error.h"
#include "penumbra/scene/scene_limits.h"
#include "penumbra/sensors/lidar_pattern.h"

namespace penumbra {
namespace {

std::string ErrorOf(const std::string& preset, int columns, double rate_hz) {
  LidarPatternOptions o;
  o.columns = columns;
  o.rate_hz = rate_hz;
  try {
    MakeLidarPattern(preset, o);
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

TEST(LidarLimits, BeamsPerScanAreCapped) {
  EXPECT_NE(ErrorOf("velodyne_vlp16", 1000000000, 0).find("expected at most 4194304"),
            std::string::npos);
  EXPECT_NE(ErrorOf("velodyne_vlp16", 0, 1e-9).find("rate_hz"), std::string::npos);
  EXPECT_NE(ErrorOf("livox_mid40", 0, 1e-6).find("expected at most 4194304"), std::string::npos);
  EXPECT_NE(ErrorOf("livox_mid40", 5000000, 0).find("expected at most 4194304"), std::string::npos);
  // the cap itself: 16 rings x 262144 columns
  LidarPatternOptions o;
  o.columns = kMaxLidarBeamsPerScan / 16;
  EXPECT_EQ(MakeLidarPattern("velodyne_vlp16", o).beams.size(),
            static_cast<size_t>(kMaxLidarBeamsPerScan));
  o.columns += 1;
  EXPECT_THROW(MakeLidarPattern("velodyne_vlp16", o), Error);
}

}  // namespace
}  // namespace penumbra
