#include "penumbra/output/camera_info.h"

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

namespace penumbra {
namespace {

std::vector<CameraSpec> StereoPair() {
  CameraSpec l;
  l.name = "head/left";
  l.body = 2;
  l.intrinsics = CameraIntrinsics::FromFovy(640, 480, 60);
  l.intrinsics.k1 = -0.1;
  l.intrinsics.p2 = 2e-4;
  CameraSpec r = l;
  r.name = "head/right";
  r.X_BO.translation() = Eigen::Vector3d(0, 0.12, 0);  // 0.12 m apart
  CameraSpec mono;
  mono.name = "top";
  mono.intrinsics = CameraIntrinsics::FromFovy(320, 240, 40);
  return {l, r, mono};
}

TEST(CameraInfoTest, RecordsHaveRosCameraInfoFields) {
  const std::vector<CameraInfo> infos = CameraInfosFor(StereoPair());
  ASSERT_EQ(infos.size(), 3u);
  EXPECT_EQ(infos[0].baseline_m, 0);
  EXPECT_NEAR(infos[1].baseline_m, 0.12, 1e-12);
  const nlohmann::json j = nlohmann::json::parse(CameraInfoJson(infos));
  const nlohmann::json& r = j["head/right"];
  const CameraIntrinsics k = StereoPair()[1].intrinsics;
  EXPECT_EQ(r["distortion_model"], "plumb_bob");
  EXPECT_EQ(r["width"], 640);
  EXPECT_EQ(r["height"], 480);
  EXPECT_EQ(r["D"].size(), 5u);
  EXPECT_EQ(r["D"][0].get<double>(), -0.1);
  EXPECT_EQ(r["D"][3].get<double>(), 2e-4);
  EXPECT_EQ(r["K"][0].get<double>(), k.fx);
  EXPECT_EQ(r["K"][2].get<double>(), k.cx);
  EXPECT_EQ(r["K"][4].get<double>(), k.fy);
  EXPECT_EQ(r["K"][5].get<double>(), k.cy);
  EXPECT_EQ(r["R"][0].get<double>(), 1);
  EXPECT_NEAR(r["P"][3].get<double>(), -k.fx * 0.12, 1e-9);  // Tx = -fx * baseline
  EXPECT_EQ(j["head/left"]["P"][3].get<double>(), 0);
  EXPECT_EQ(j["top"]["frame_id"], "top/optical");
  const std::string yaml = CameraInfoYaml(infos);
  EXPECT_NE(yaml.find("distortion_model: plumb_bob"), std::string::npos);
  EXPECT_NE(yaml.find("\"head/right\":"), std::string::npos);
}

}  // namespace
}  // namespace penumbra
