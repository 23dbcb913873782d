#pragma once
// a height field sampled from static geometry by casting rays straight down (docs/environments.md
// "Height fields"): for robust, fast robot-terrain contact, a terrain mesh's collision becomes a
// MuJoCo hfield (MuJoCo XML reference, <hfield>) of the heights the rays hit.
//
// sampling: the grid has `cols` x `rows` samples spaced cell_m apart, sample (r, c) at
// (x0 + c cell_m, y0 + r cell_m); each is the height of the first surface a ray from z_top
// straight down (-z) hits, the highest surface there (overhangs are filled). a ray that hits
// nothing gives z_miss.
//
// error: between samples MuJoCo interpolates the grid linearly over two triangles per cell, so
// the sampled surface differs from the geometry by at most about cell_m x the largest slope
// change within a cell (one cell's slope error); ErrorAtCellCentres measures it where it is
// largest for smooth terrain, halfway between the samples.

#include <Eigen/Geometry>
#include <vector>

#include "penumbra/render/ray_query.h"

namespace penumbra {

/// heights on a regular grid in the world frame.
struct SampledHeightField {
  int rows = 0, cols = 0;  ///< samples along y and x
  double x0 = 0, y0 = 0;   ///< the first sample's position, m
  double cell_m = 0.1;     ///< spacing, m
  std::vector<double> z;   ///< (rows x cols) row-major, row 0 at y0, m
  int misses = 0;          ///< rays that hit nothing (their z is z_miss)

  /// the height at (x, y) interpolated linearly over two triangles per cell (split along the
  /// diagonal from (c, r) to (c + 1, r + 1)); clamped to the grid.
  double HeightAt(double x, double y) const;
};

/// samples `query` (posed by the caller) over the plan rectangle [lo, hi] (x, y; m) with
/// spacing cell_m: cols = floor((hi.x - lo.x) / cell_m) + 1 (likewise rows), so the grid starts
/// at lo and may end short of hi by less than a cell.
/// @throws Error if cell_m <= 0, the rectangle is empty, or the grid exceeds 4096 x 4096.
SampledHeightField SampleHeightField(const RayQuery& query, const Eigen::Vector2d& lo,
                                     const Eigen::Vector2d& hi, double cell_m, double z_top,
                                     double z_miss);

/// |sampled - geometry| at the centre of every cell whose four samples hit (rays cast there):
/// the largest and the mean, m.
struct HeightFieldError {
  double max_m = 0, mean_m = 0;
  int cells = 0;
};
HeightFieldError ErrorAtCellCentres(const RayQuery& query, const SampledHeightField& field,
                                    double z_top);

}  // namespace penumbra
