#pragma once
// the host buffers of a pathtraced frame on the GPU (cuda_path.h fills them, path_frame.h
// finishes them). C++17, no Eigen: path_kernels.cu includes it.

#include <cstdint>
#include <vector>

#include "penumbra/render/shading_math.h"

namespace penumbra::cuda {

/// per pixel of a pathtraced frame (width x height, row-major): PathFrameView's outputs.
struct PathBuffers {
  std::vector<Float3> radiance, albedo, normal;
  std::vector<float> depth;
  /// sizes every buffer to n pixels.
  void Resize(int64_t n) {
    radiance.resize(n);
    albedo.resize(n);
    normal.resize(n);
    depth.resize(n);
  }
};

}  // namespace penumbra::cuda
