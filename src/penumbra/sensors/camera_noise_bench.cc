#include <algorithm>
#include <chrono>
#include <memory>

#include "penumbra/render/backends/renderer_factory.h"
#include "penumbra/sensors/camera_imager.h"
#include "penumbra/sensors/camera_profile.h"

namespace penumbra {

std::vector<std::pair<std::string, double>> CameraNoiseBench(int frames) {
  // a box room with a lit floor, a sphere and a crate, seen by a 320 x 240 camera
  SceneDescription scene;
  scene.bodies.push_back({"world", -1, true});
  scene.sky.radiance = Eigen::Vector3f(200, 220, 250);
  Material grey, red;
  grey.name = "grey";
  red.name = "red";
  red.base_color = Eigen::Vector3f(0.7f, 0.1f, 0.1f);
  scene.materials = {grey, red};
  auto add = [&](GeomShape shape, Eigen::Vector3d size, Eigen::Vector3d pos, int material) {
    Geom g;
    g.id = static_cast<int>(scene.geoms.size());
    g.shape = shape;
    g.size = size;
    g.X_BG.translation() = pos;
    g.material = material;
    scene.geoms.push_back(g);
  };
  add(GeomShape::kBox, {10, 10, 0.05}, {0, 0, -0.05}, 0);
  add(GeomShape::kBox, {0.05, 10, 3}, {6, 0, 3}, 0);
  add(GeomShape::kSphere, {0.5, 0, 0}, {3, 0.5, 0.5}, 1);
  add(GeomShape::kBox, {0.4, 0.4, 0.4}, {2.5, -1, 0.4}, 0);
  Light sun;
  sun.type = Light::Type::kDirectional;
  sun.direction_B = Eigen::Vector3d(0.3, 0.2, -1).normalized();
  sun.intensity = 50000;
  scene.lights.push_back(sun);
  RenderSettings rs;
  rs.tier = RenderSettings::Tier::kRealtime;
  auto renderer = MakeRenderer(scene, rs);
  CameraSpec spec;
  spec.name = "bench";
  spec.intrinsics = CameraIntrinsics::FromFovy(320, 240, 60);
  spec.outputs = CameraOutputs{ImageKind::kRgb, ImageKind::kDepth};
  Pose X0 = Pose::Identity();
  X0.linear() = RotationBodyFromOptical();
  X0.translation() = Eigen::Vector3d(0, 0, 1);
  Pose X1 = X0;
  X1.translation() += Eigen::Vector3d(0.05, 0.02, 0);
  WorldSnapshot a;
  a.X_WB.assign(1, Pose::Identity());
  WorldSnapshot b = a;
  b.time_sec = 0.02;
  auto wet = std::make_shared<EffectsFrame>();
  ParticleSet rain;
  rain.kind = ParticleKind::kRain;
  rain.position_W.push_back(Eigen::Vector3f(100, 100, 100));
  rain.velocity_W.push_back(Eigen::Vector3f(0, 0, -5));
  rain.radius_m.push_back(0.001f);
  wet->particles.push_back(rain);

  std::vector<std::pair<std::string, CameraSensorConfig>> options;
  CameraSensorConfig none;
  options.emplace_back("none", none);
  CameraSensorConfig c = none;
  c.noise.enabled = true;
  options.emplace_back("shot_read", c);
  c = none;
  c.motion_blur_samples = 4;
  options.emplace_back("motion_blur_4", c);
  c = none;
  c.rolling_shutter_line_time_sec = 3e-5;
  options.emplace_back("rolling_shutter", c);
  c = none;
  c.jpeg_quality = 80;
  options.emplace_back("jpeg_q80", c);
  c = none;
  c.lens_droplet_count = 8;
  options.emplace_back("lens_droplets", c);
  c = none;
  c.depth_noise.preset = "realsense_d435";
  options.emplace_back("depth_realsense_d435", c);
  c.noise.enabled = true;
  c.motion_blur_samples = 4;
  c.rolling_shutter_line_time_sec = 3e-5;
  c.jpeg_quality = 80;
  options.emplace_back("all", c);
  // the named camera profiles (moving, so their shutter and readout act), then every option
  for (CameraProfile p : {CameraProfile::kRealsenseD435Rgb, CameraProfile::kBlackflySImx250})
    options.emplace_back("profile_" + std::string(CameraProfileName(p)), CameraProfileConfig(p));

  std::vector<std::pair<std::string, double>> out;
  for (auto& [name, cfg] : options) {
    CameraImager imager(spec, cfg, rs, 0, scene);
    const EffectsFrame* fx = name == "lens_droplets" || name == "all" ? wet.get() : nullptr;
    const bool moving = cfg.motion_blur_samples > 1 || RowTimeSec(cfg, spec.intrinsics.height) > 0;
    // the end snapshot no earlier than the frame's span (a profile's longest shutter + readout)
    WorldSnapshot end = b;
    end.time_sec = std::max(b.time_sec, FrameSpanSec(cfg, spec.intrinsics.height));
    CameraImages img;
    const auto t0 = std::chrono::steady_clock::now();
    for (int f = 0; f < frames; ++f)
      imager.Capture(renderer.get(), a, fx, X0, moving ? &end : nullptr, X1, f, &img);
    const double sec = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    out.emplace_back(name, frames / std::max(sec, 1e-9));
  }
  return out;
}

}  // namespace penumbra
