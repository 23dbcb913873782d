#pragma once
// `penumbra make-vdb`: writes a small procedural smoke cloud as an OpenVDB file (a float
// grid named "density"), for the vdb_smoke example world (worlds/effects/vdb_smoke.yaml)
// and for trying the vdb_smoke effect without a fluid-simulation package.

#include <array>
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

/// what MakeSmokeVdb wrote.
struct SmokeVdbSummary {
  std::string path;                ///< the file
  uintmax_t file_bytes = 0;        ///< its size
  std::string grid = "density";    ///< the one grid's name
  int64_t active_voxels = 0;       ///< voxels with a density > 0
  double voxel_m = 0;              ///< voxel edge, m
  std::array<int, 3> index_min{};  ///< bounding box of the active voxels, voxel indices
  std::array<int, 3> index_max{};  ///< (inclusive); world position = index * voxel_m
  float max_density = 0;           ///< largest voxel value (at most 1)
};

/// one line for the user: the file, its size, the grid, its voxel count, voxel size and extent.
std::string DescribeSmokeVdb(const SmokeVdbSummary& s);

/// writes `path`: a float grid "density" in [0, 1] in steps of 1/32 (zero voxels inactive;
/// zip-compressed), centred on
/// the origin with its bottom at z = 0, made of `blobs` Gaussian puffs
/// rho = exp(-|x - c|^2 / (2 s^2)) summed and clamped to 1; world transform = voxel_m scale.
/// deterministic: the same options give the same grid.
/// @throws ConfigError for out-of-range options or a file that cannot be written.
/// @returns what it wrote.
SmokeVdbSummary MakeSmokeVdb(const std::string& path, const SmokeVdbOptions& options);

}  // namespace penumbra
