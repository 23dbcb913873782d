#pragma once
// the grid media's arrays (render/media/media_scene_math.h's MediaGridPod: densities and emission)
// copied to the device, for the pathtraced kernels (DevicePath::UploadMedia) and the
// realtime tier's grid volume kernels (DeviceRealtime). includes the CUDA
// runtime header (cuda_device_buffer.h): only .cu files include this.

#include <cuda_runtime.h>

#include <cstddef>
#include <vector>

#include "penumbra/render/cuda/cuda_device_buffer.h"
#include "penumbra/render/media/media_scene_math.h"

namespace penumbra::cuda {

/// copies the n grids `h` (host pointers) to the device on `stream` (pageable memory: staged
/// before the calls return): every grid's density (and emission, where it has one) end to end
/// in *density (and *emission), their pods with device pointers into them in *pods. returns the
/// device pods (null for n = 0). the buffers grow as needed (earlier device copies then move).
/// `arrays` false: the densities and emission are already there (an earlier call's, for grids
/// of the same sizes): only the pods are copied, pointing at them.
/// @throws Error on a CUDA failure.
inline const MediaGridPod* UploadMediaGrids(const MediaGridPod* h, int n, Buffer* density,
                                            Buffer* emission, Buffer* pods, cudaStream_t stream,
                                            bool arrays = true) {
  std::vector<MediaGridPod> grids(h, h + n);
  size_t density_n = 0, emission_n = 0;
  for (const MediaGridPod& g : grids) {
    const size_t cells = static_cast<size_t>(g.n[0]) * g.n[1] * g.n[2];
    density_n += cells;
    if (g.emission != nullptr) emission_n += 3 * cells;
  }
  if (arrays) {
    density->Reserve(sizeof(float) * (density_n > 0 ? density_n : 1));
    emission->Reserve(sizeof(float) * (emission_n > 0 ? emission_n : 1));
  }
  size_t density_at = 0, emission_at = 0;
  for (MediaGridPod& g : grids) {
    const size_t cells = static_cast<size_t>(g.n[0]) * g.n[1] * g.n[2];
    float* dd = density->as<float>() + density_at;
    if (arrays && cells > 0)
      Check(cudaMemcpyAsync(dd, g.density, sizeof(float) * cells, cudaMemcpyHostToDevice, stream),
            "uploading a grid's density");
    g.density = dd;
    density_at += cells;
    if (g.emission != nullptr) {
      float* de = emission->as<float>() + emission_at;
      if (arrays && cells > 0)
        Check(cudaMemcpyAsync(de, g.emission, sizeof(float) * 3 * cells, cudaMemcpyHostToDevice,
                              stream),
              "uploading a grid's emission");
      g.emission = de;
      emission_at += 3 * cells;
    }
  }
  pods->Upload(grids.data(), sizeof(MediaGridPod) * grids.size(), stream);
  return n > 0 ? pods->as<MediaGridPod>() : nullptr;
}

}  // namespace penumbra::cuda
