#include "penumbra/world/run_budget.h"

#include <fmt/format.h>
#include <unistd.h>

#include <cmath>

#include "penumbra/core/error.h"
#include "penumbra/sensors/lidar_pattern.h"
#include "penumbra/world/camera_specs.h"

namespace penumbra {
namespace {

int NumOutputs(const CameraOutputs& o) { return o.count(); }

// uncompressed bytes per pixel of the images a camera writes (scene/image_kind.h: rgb and
// normals 8-bit x 3, the others 16-bit x 1).
double ImageBytesPerPixel(const CameraOutputs& o) {
  double bytes = 0;
  for (const ImageKindInfo& k : kImageKinds)
    if (o[k.kind]) bytes += EncodedBytesPerPixel(k.encoding);
  return bytes;
}

std::string Bytes(double b) {
  if (b >= 1e9) return fmt::format("{:.1f} GB", b / 1e9);
  return fmt::format("{:.0f} MB", b / 1e6);
}

// the world-file key that sets a camera's size, and the line it is on.
std::string CameraSizeKey(const WorldConfig& world, const CameraSpec& c) {
  if (c.mjcf_camera >= 0) {
    for (const CameraConfig& o : world.mjcf_cameras.overrides)
      if (o.name == c.name) return "mjcf_cameras.overrides." + o.name + ".width";
    return "mjcf_cameras.width";
  }
  for (size_t i = 0; i < world.cameras.size(); ++i) {
    const std::string& n = world.cameras[i].name;
    if (c.name == n || c.name == n + "/left" || c.name == n + "/right")
      return "cameras[" + std::to_string(i) + "].width";
  }
  return "cameras";
}

// the beams per scan and scan rate of a LiDAR entry (as sinks/sensor_sink.cc builds it);
// nothing when the pattern is invalid (the sensor stage reports that with the key).
std::optional<std::pair<double, double>> LidarBeams(const SensorConfig& s) {
  const LidarSensorParams* lidar = s.get<LidarSensorParams>();
  if (!lidar) return std::nullopt;
  LidarPatternOptions po;
  po.columns = lidar->columns;
  po.rate_hz = s.rate_hz.value_or(0);
  try {
    const LidarPattern p = MakeLidarPattern(lidar->preset, po);
    return std::make_pair(static_cast<double>(p.beams.size()), p.rate_hz);
  } catch (const Error&) {
    return std::nullopt;
  }
}

}  // namespace

double EstimateCameraMemoryBytes(const CameraSpec& camera, RenderSettings::Tier tier) {
  const double pixels =
      static_cast<double>(camera.intrinsics.width) * static_cast<double>(camera.intrinsics.height);
  const double per_pixel =
      (tier == RenderSettings::Tier::kPathtraced ? kCameraBytesPerPixelPathtraced
                                                 : kCameraBytesPerPixelRealtime) +
      kCameraBytesPerPixelPerOutput * std::max(0, NumOutputs(camera.outputs) - 1);
  return pixels * per_pixel;
}

double PhysicalMemoryBytes() {
  const long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGE_SIZE);
  return pages > 0 && page > 0 ? static_cast<double>(pages) * static_cast<double>(page) : 0.0;
}

void CheckRunMemory(const WorldConfig& world, const SceneDescription& scene, double limit_bytes) {
  if (!(limit_bytes > 0)) return;
  double total = 0;
  for (const CameraSpec& c : scene.cameras) {
    const double bytes = EstimateCameraMemoryBytes(c, world.render.tier);
    total += bytes;
    if (total > limit_bytes) {
      throw ConfigError(world.file, 0, CameraSizeKey(world, c),
                        fmt::format("camera '{}' at {} x {} needs about {} (~{:.0f} bytes per "
                                    "pixel), {} for all cameras so far, more than the {} of "
                                    "memory available; expected smaller images or fewer cameras",
                                    c.name, c.intrinsics.width, c.intrinsics.height, Bytes(bytes),
                                    bytes / (double(c.intrinsics.width) * c.intrinsics.height),
                                    Bytes(total), Bytes(limit_bytes)));
    }
  }
  for (const SensorConfig& s : world.sensors) {
    const auto beams = LidarBeams(s);
    if (!beams) continue;
    const double bytes = beams->first * kLidarBytesPerBeam;
    total += bytes;
    if (total > limit_bytes) {
      throw ConfigError(
          s.file, s.line, s.key + ".columns",
          fmt::format("sensor '{}': {:.0f} beams per scan need about {}, {} with the "
                      "cameras, more than the {} of memory available; expected "
                      "fewer columns",
                      s.name, beams->first, Bytes(bytes), Bytes(total), Bytes(limit_bytes)));
    }
  }
}

RunWork EstimateRunWork(const WorldConfig& world, const SceneDescription& scene,
                        double timestep_sec) {
  RunWork w;
  const double t = world.duration_sec;
  if (timestep_sec > 0) w.physics_steps = std::ceil(t / timestep_sec);
  const std::vector<CameraSensorConfig> sensor = SensorConfigsFor(scene, world);
  for (size_t i = 0; i < scene.cameras.size(); ++i) {
    const CameraSpec& c = scene.cameras[i];
    const double frames = std::floor(t * c.rate_hz) + 1;  // frame 0 at t = 0
    const double pixels = double(c.intrinsics.width) * double(c.intrinsics.height);
    w.camera_frames += frames;
    w.image_bytes += frames * pixels * ImageBytesPerPixel(c.outputs);
    if (world.render.tier == RenderSettings::Tier::kPathtraced && c.outputs[ImageKind::kRgb]) {
      const int blur = i < sensor.size() ? std::max(1, sensor[i].motion_blur_samples) : 1;
      w.path_samples += frames * pixels * world.render.samples_per_pixel * blur;
    }
  }
  for (const SensorConfig& s : world.sensors)
    if (const auto beams = LidarBeams(s)) w.lidar_rays += beams->first * (t * beams->second + 1);
  for (const EffectConfig& e : world.effects)
    if (const std::optional<double> dt = EffectFluidDtSec(e)) w.fluid_steps += t / *dt;
  return w;
}

std::optional<std::string> DescribeRunWork(const RunWork& w) {
  if (!(w.physics_steps > kWarnPhysicsSteps || w.camera_frames > kWarnCameraFrames ||
        w.image_bytes > kWarnImageBytes || w.lidar_rays > kWarnLidarRays ||
        w.fluid_steps > kWarnFluidSteps || w.path_samples > kWarnPathSamples))
    return std::nullopt;
  std::string s =
      fmt::format("this run will take ~{:.3g} physics steps and {:.3g} frames (~{} of images)",
                  w.physics_steps, w.camera_frames, Bytes(w.image_bytes));
  if (w.lidar_rays > 0) s += fmt::format(", {:.3g} LiDAR rays", w.lidar_rays);
  if (w.fluid_steps > 0) s += fmt::format(", {:.3g} smoke/fire grid steps", w.fluid_steps);
  if (w.path_samples > 0)
    s += fmt::format(", {:.3g} path samples (pathtraced: pixels x samples_per_pixel x frames)",
                     w.path_samples);
  s += fmt::format(
      "; warned above {:.0e} steps, {:.0e} frames, {}, {:.0e} rays, {:.0e} grid steps or {:.0e} "
      "path samples (docs/world-file.md \"Input limits\"): check duration_sec, "
      "physics.timestep_sec, the camera rates and sizes and render.samples_per_pixel (--spp)",
      kWarnPhysicsSteps, kWarnCameraFrames, Bytes(kWarnImageBytes), kWarnLidarRays, kWarnFluidSteps,
      kWarnPathSamples);
  return s;
}

}  // namespace penumbra
