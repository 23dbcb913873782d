#pragma once
// the CUDA backend against the CPU backend on one world: the world's first
// camera at `width` x `height` after 1 s of simulation, both backends built by MakeRenderer.
// depth within 1 mm and segmentation equal are counted on the clear frame (no effects: the
// geometry both backends trace); the rgb PSNR is that of the frame with the world's effects, if
// it has any (every frame renders on the GPU: lighting effects, particles,
// homogeneous and grid media, particles seen through media, the pathtraced tier's media and
// particles). shared by
// render_cuda_bench --parity
// (scripts/gpu/parity.sh) and the `gpu` test CudaParity. header-only: both link the same libraries.

#include <fmt/format.h>

#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "penumbra/physics/simulation.h"
#include "penumbra/render/backends/renderer_factory.h"
#include "penumbra/render/cuda/cuda_renderer.h"
#include "penumbra/scene/camera_pose.h"
#include "penumbra/session/session.h"
#include "penumbra/world/world_config.h"

namespace penumbra::cuda_parity {

/// one world's parity.
struct ParityRow {
  std::string world;
  int pixels = 0;
  int hit = 0;                  ///< pixels the CPU backend's depth hit
  double depth_within_1mm = 0;  ///< % of pixels
  double seg_equal = 0;         ///< % of pixels
  int ties = 0;                 ///< of the differing ids: same depth within 1e-5 (coplanar)
  bool effects = false;         ///< the world has effects at 1 s
  std::string rgb;              ///< "PSNR x dB"
  double rgb_psnr = -1;         ///< the rgb PSNR (dB; 99 equal) where rgb is on the GPU, else -1
};

/// measures `world_file` (see the file comment). needs a CUDA device.
inline ParityRow MeasureParity(const std::string& world_file, int width, int height) {
  SessionOptions so;
  so.build_renderer = false;
  so.add_controllers = false;
  Session session(LoadWorldFile(world_file), so);
  Simulation& sim = session.sim();
  while (sim.time() < 1.0 - 1e-9) sim.Step();
  const WorldSnapshot snap = sim.Snapshot();
  const SceneDescription& scene = session.scene();
  const CameraSpec& cam = scene.cameras.front();
  CameraView view;
  view.X_WO = CameraPoseInWorld(cam, snap);
  const double fovy_deg = cam.intrinsics.fovy_deg();
  view.intrinsics = CameraIntrinsics::FromFovy(width, height, fovy_deg);
  view.near_m = cam.near_m;
  view.exposure_time_sec = cam.exposure_time_sec;
  view.frame_index = snap.step;
  view.outputs[ImageKind::kRgb] = false;
  view.outputs[ImageKind::kDepth] = view.outputs[ImageKind::kSegmentation] = true;
  const std::shared_ptr<const EffectsFrame> fx =
      session.effects().Evaluate(snap, view.X_WO.translation());
  RenderSettings cpu_settings;
  cpu_settings.backend = RenderSettings::Backend::kEmbree;
  cpu_settings.seed = 1;
  RenderSettings gpu_settings = cpu_settings;
  gpu_settings.backend = RenderSettings::Backend::kCuda;
  const std::unique_ptr<Renderer> cpu = MakeRenderer(scene, cpu_settings);
  const std::unique_ptr<Renderer> gpu = MakeRenderer(scene, gpu_settings);
  ParityRow row;
  row.world = world_file.substr(
      world_file.find("worlds/") == std::string::npos ? 0 : world_file.find("worlds/") + 7);
  RenderedFrame a, b;
  cpu->Render(snap, nullptr, view, &a);
  gpu->Render(snap, nullptr, view, &b);
  const int n = width * height;
  row.pixels = n;
  int depth_ok = 0, seg_ok = 0;
  for (int i = 0; i < n; ++i) {
    const float da = a.depth_m.data[i], db = b.depth_m.data[i];
    row.hit += da > 0;
    depth_ok += std::abs(da - db) <= 1e-3f;
    const bool same = a.geom_id.data[i] == b.geom_id.data[i];
    seg_ok += same;
    row.ties += !same && da > 0 && std::abs(da - db) <= 1e-5f * (1 + da);
  }
  row.depth_within_1mm = 100.0 * depth_ok / n;
  row.seg_equal = 100.0 * seg_ok / n;
  row.effects = fx && !fx->empty();
  CameraView rgb_view = view;
  rgb_view.outputs[ImageKind::kRgb] = true;
  RenderedFrame ca, cb;
  cpu->Render(snap, fx.get(), rgb_view, &ca);
  gpu->Render(snap, fx.get(), rgb_view, &cb);
  double se = 0;
  for (size_t i = 0; i < ca.rgb.data.size(); ++i) {
    const double d = static_cast<double>(ca.rgb.data[i]) - cb.rgb.data[i];
    se += d * d;
  }
  const double mse = se / std::max<size_t>(1, ca.rgb.data.size());
  row.rgb_psnr = mse == 0 ? 99.0 : 10 * std::log10(255.0 * 255.0 / mse);
  row.rgb = mse == 0 ? "PSNR inf (equal)"
                     : fmt::format("PSNR {:.1f} dB", 10 * std::log10(255.0 * 255.0 / mse));
  return row;
}

/// the rows as a markdown table.
inline std::string FormatParity(const std::vector<ParityRow>& rows, int width, int height) {
  std::string s = fmt::format(
      "| world ({}x{}, first camera, t = 1 s) | pixels hit | depth within 1 mm | seg equal | "
      "same-depth ties | seg equal, ties apart | effects frame | rgb |\n"
      "|---|---:|---:|---:|---:|---:|---|---|\n",
      width, height);
  for (const ParityRow& r : rows)
    s += fmt::format("| {} | {} of {} | {:.3f} % | {:.3f} % | {} | {:.3f} % | {} | {} |\n", r.world,
                     r.hit, r.pixels, r.depth_within_1mm, r.seg_equal, r.ties,
                     r.seg_equal + 100.0 * r.ties / r.pixels, r.effects ? "on GPU" : "none", r.rgb);
  return s;
}

}  // namespace penumbra::cuda_parity
