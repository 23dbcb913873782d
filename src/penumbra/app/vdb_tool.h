#pragma once
// `penumbra make-vdb`: writes a small procedural smoke cloud as an OpenVDB file (a float
// grid named "density"), for the vdb_smoke example world (worlds/effects/vdb_smoke.yaml)
// and for trying the vdb_smoke effect without a fluid-simulation package.

#include <cstdint>
#include <string>

namespace penumbra {

/// options of MakeSmokeVdb.
struct SmokeVdbOptions {
  uint64_t seed = 1;      ///< keys the blob positions and sizes (core/rng.h)
  double voxel_m = 0.05;  ///< voxel size, m, (0.005, 1]
  double radius_m = 0.6;  ///< radius of the cloud, m, (voxel_m, 20]
  int blobs = 8;          ///< Gaussian blobs making up the cloud, [1, 64]
};

/// writes `path`: a float grid "density" in [0, 1] in steps of 1/32 (zero voxels inactive;
/// zip-compressed), centred on
/// the origin with its bottom at z = 0, made of `blobs` Gaussian puffs
/// rho = exp(-|x - c|^2 / (2 s^2)) summed and clamped to 1; world transform = voxel_m scale.
/// deterministic: the same options give the same grid.
/// @throws ConfigError for out-of-range options or a file that cannot be written.
void MakeSmokeVdb(const std::string& path, const SmokeVdbOptions& options);

}  // namespace penumbra
