#pragma once
// a small smoke / fire fluid on a box: Stam, "Stable Fluids", SIGGRAPH 1999 (collocated
// grid with one ghost layer, semi-Lagrangian advection with trilinear interpolation,
// pressure projection by Jacobi iterations, closed no-through walls), with the buoyancy of
// Fedkiw, Stam, Jensen, "Visual Simulation of Smoke", SIGGRAPH 2001 (see FluidParams).
//
// one Step(), in this order: sources (emitters add mass rate * dt spread over the voxels
// inside their radius, raise the temperature excess to T_e - T_amb, and kick the velocity
// by a seeded random horizontal amount), buoyancy, velocity self-advection, projection,
// scalar advection by velocity + wind, decay (density x exp(-k dt), temperature excess
// x exp(-cooling dt)).
// walls: with zero wind the box is closed and the scalar advection step is rescaled so
// the total mass is unchanged (the continuous advection of a divergence-free field in a
// closed box conserves it; semi-Lagrangian interpolation alone does not: without the
// rescale the plume of tests/effects/grid_fluid_test.cc loses 23% of its mass in 3 s); with wind,
// clean air flows in upwind and smoke leaves downwind.
// units: metres, seconds; density dimensionless (mass = sum density x voxel volume, m^3).
// deterministic: single-threaded, every random draw keyed by (key, step, emitter).

#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <vector>

#include "penumbra/effects/types/fluid_params.h"
#include "penumbra/scene/effects_frame.h"

namespace penumbra {

/// the fluid state of one smoke / fire effect.
class GridFluid {
 public:
  /// grid over `region`: resolution voxels along its longest axis, at least 4 on every axis.
  GridFluid(const FluidParams& params, const BoxRegion& region, const Eigen::Vector3d& wind_m_s,
            uint64_t key);

  /// back to the t = 0 state (all zero, step count 0).
  void Reset();
  /// advances one dt; `emission_weight` in [0, 1] scales the emitters (the effect's weight).
  void Step(double emission_weight);

  /// steps (from Reset() when t went backwards) until steps() = floor(t_sec / dt_sec),
  /// each step k with emission weight emission_weight_at(k * dt_sec).
  void AdvanceTo(double t_sec, const std::function<double(double)>& emission_weight_at);

  int steps() const { return steps_; }
  int nx() const { return nx_; }
  int ny() const { return ny_; }
  int nz() const { return nz_; }
  /// voxel size per axis, m.
  const Eigen::Vector3d& voxel_size() const { return h_; }
  const BoxRegion& region() const { return region_; }

  /// density of interior voxel (i, j, k), 0-based.
  float density(int i, int j, int k) const { return rho_[Ix(i + 1, j + 1, k + 1)]; }
  /// absolute temperature of voxel (i, j, k), K.
  double temperature_k(int i, int j, int k) const {
    return params_.ambient_temperature_k + theta_[Ix(i + 1, j + 1, k + 1)];
  }
  /// world position of the centre of voxel (i, j, k).
  Eigen::Vector3d VoxelCentre(int i, int j, int k) const;
  /// sum of density x voxel volume, m^3.
  double TotalMass() const;
  /// density-weighted centre, world frame (region centre when empty).
  Eigen::Vector3d CentreOfMass() const;
  /// (nz x ny x nx) densities, index (k * ny + j) * nx + i (the GridMedium layout).
  std::vector<float> DensityGrid() const;
  /// largest density.
  float MaxDensity() const;

 private:
  size_t Ix(int i, int j, int k) const {
    return (static_cast<size_t>(k) * (ny_ + 2) + j) * (nx_ + 2) + i;
  }
  void SetBoundary(int b, std::vector<float>& x) const;
  // advects `count` fields (boundary kinds b) along the velocity + extra_velocity.
  void Advect(int count, const int* b, std::vector<float>* const* dst,
              const std::vector<float>* const* src, const Eigen::Vector3d& extra_velocity,
              bool open) const;
  void Project();

  FluidParams params_;
  BoxRegion region_;
  Eigen::Vector3d wind_;
  uint64_t key_;
  int nx_ = 4, ny_ = 4, nz_ = 4;
  Eigen::Vector3d h_;
  double voxel_volume_ = 0;
  int steps_ = 0;
  std::vector<float> rho_, theta_, u_, v_, w_, tmp_, p_, div_;
  std::vector<std::vector<size_t>> emitter_cells_;
};

/// a GridMedium on the axis-aligned box `region` with nx x ny x nz voxels (the GridFluid
/// layout); density, coefficients and emission left empty.
GridMedium RegionGridMedium(const BoxRegion& region, int nx, int ny, int nz);

}  // namespace penumbra
