// the parity of the CUDA backend with the CPU backend (ctest label `gpu`) on
// the worlds cuda_backend_gpu_test.cc does not cover: the outdoor world and every
// worlds/effects/*.yaml (cuda_parity.h, as scripts/gpu/parity.sh prints them): on the clear
// frame depth within 1 mm on >= 99.9 % of pixels and segmentation equal on >= 99.9 % (same-depth
// ties of coplanar geoms counted apart); where the frame with the world's effects renders on the
// GPU (every effect: lighting effects: blackout, flashlight, sun; particles:
// rain, snow; homogeneous media: fog, height_fog, dust; grid media: smoke_plume, fire,
// vdb_smoke; all of them with rain seen through media: adversity_major), its rgb PSNR >= 40 dB
// against the CPU backend.
// without a device: "skipped: no CUDA device".

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "render/cuda/cuda_parity.h"

namespace penumbra {
namespace {

std::vector<std::string> ParityWorldFiles() {
  const std::string dir = std::string(PENUMBRA_SOURCE_DIR) + "/worlds/";
  std::vector<std::string> files = {dir + "outdoor.yaml"};
  std::vector<std::string> effects;
  for (const auto& e : std::filesystem::directory_iterator(dir + "effects"))
    if (e.path().extension() == ".yaml") effects.push_back(e.path().string());
  std::sort(effects.begin(), effects.end());
  files.insert(files.end(), effects.begin(), effects.end());
  return files;
}

TEST(CudaParity, OutdoorAndEffectsWorldsMatchTheCpuBackend) {
  if (!ProbeCudaDevice().available) GTEST_SKIP() << "skipped: no CUDA device";
  std::vector<cuda_parity::ParityRow> rows;
  int gpu_effects = 0;
  for (const std::string& file : ParityWorldFiles()) {
    SCOPED_TRACE(file);
    const cuda_parity::ParityRow r = cuda_parity::MeasureParity(file, 160, 120);
    EXPECT_GE(r.depth_within_1mm, 99.9);
    EXPECT_GE(r.seg_equal + 100.0 * r.ties / r.pixels, 99.9);
    EXPECT_GE(r.rgb_psnr, 40.0);
    gpu_effects += r.effects;
    rows.push_back(r);
  }
  std::printf("%s", cuda_parity::FormatParity(rows, 160, 120).c_str());
  EXPECT_GE(rows.size(), 10u);
  // blackout, flashlight, sun, rain, snow, fog, height_fog, dust, smoke_plume, fire, vdb_smoke
  // and adversity_major render their effects frames on the GPU
  EXPECT_GE(gpu_effects, 12);
}

}  // namespace
}  // namespace penumbra
