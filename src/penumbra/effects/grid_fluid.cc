#include "penumbra/effects/grid_fluid.h"

#include <algorithm>
#include <cmath>

#include "penumbra/core/rng.h"

namespace penumbra {

GridFluid::GridFluid(const FluidParams& params, const BoxRegion& region,
                     const Eigen::Vector3d& wind_m_s, uint64_t key)
    : params_(params), region_(region), wind_(wind_m_s), key_(key) {
  const Eigen::Vector3d ext = region.max_W - region.min_W;
  const double cell = ext.maxCoeff() / params.resolution;
  nx_ = std::max(4, static_cast<int>(std::lround(ext.x() / cell)));
  ny_ = std::max(4, static_cast<int>(std::lround(ext.y() / cell)));
  nz_ = std::max(4, static_cast<int>(std::lround(ext.z() / cell)));
  h_ = Eigen::Vector3d(ext.x() / nx_, ext.y() / ny_, ext.z() / nz_);
  voxel_volume_ = h_.prod();
  // voxels fed by each emitter: centres within its radius, else the voxel that holds it
  for (const PlumeEmitter& e : params.emitters) {
    std::vector<size_t> cells;
    for (int k = 0; k < nz_; ++k)
      for (int j = 0; j < ny_; ++j)
        for (int i = 0; i < nx_; ++i)
          if ((VoxelCentre(i, j, k) - e.position_W).norm() <= e.radius_m)
            cells.push_back(Ix(i + 1, j + 1, k + 1));
    if (cells.empty()) {
      const Eigen::Vector3d g = (e.position_W - region.min_W).cwiseQuotient(h_);
      const int i = std::clamp(static_cast<int>(g.x()), 0, nx_ - 1);
      const int j = std::clamp(static_cast<int>(g.y()), 0, ny_ - 1);
      const int k = std::clamp(static_cast<int>(g.z()), 0, nz_ - 1);
      cells.push_back(Ix(i + 1, j + 1, k + 1));
    }
    emitter_cells_.push_back(std::move(cells));
  }
  Reset();
}

void GridFluid::Reset() {
  const size_t n = static_cast<size_t>(nx_ + 2) * (ny_ + 2) * (nz_ + 2);
  for (auto* f : {&rho_, &theta_, &u_, &v_, &w_, &tmp_, &p_, &div_}) f->assign(n, 0.0f);
  steps_ = 0;
}

Eigen::Vector3d GridFluid::VoxelCentre(int i, int j, int k) const {
  return region_.min_W +
         Eigen::Vector3d((i + 0.5) * h_.x(), (j + 0.5) * h_.y(), (k + 0.5) * h_.z());
}

void GridFluid::SetBoundary(int b, std::vector<float>& x) const {
  // b = 0 scalar (zero normal gradient), 1/2/3 velocity component normal to x/y/z walls
  for (int k = 1; k <= nz_; ++k)
    for (int j = 1; j <= ny_; ++j) {
      x[Ix(0, j, k)] = b == 1 ? -x[Ix(1, j, k)] : x[Ix(1, j, k)];
      x[Ix(nx_ + 1, j, k)] = b == 1 ? -x[Ix(nx_, j, k)] : x[Ix(nx_, j, k)];
    }
  for (int k = 1; k <= nz_; ++k)
    for (int i = 0; i <= nx_ + 1; ++i) {
      x[Ix(i, 0, k)] = b == 2 ? -x[Ix(i, 1, k)] : x[Ix(i, 1, k)];
      x[Ix(i, ny_ + 1, k)] = b == 2 ? -x[Ix(i, ny_, k)] : x[Ix(i, ny_, k)];
    }
  for (int j = 0; j <= ny_ + 1; ++j)
    for (int i = 0; i <= nx_ + 1; ++i) {
      x[Ix(i, j, 0)] = b == 3 ? -x[Ix(i, j, 1)] : x[Ix(i, j, 1)];
      x[Ix(i, j, nz_ + 1)] = b == 3 ? -x[Ix(i, j, nz_)] : x[Ix(i, j, nz_)];
    }
}

// trilinear sample at grid coordinates (x, y, z) where interior voxel centres sit at
// 1..n. closed: clamped to [0.5, n + 0.5]; open: 0 outside that range (clean air).
float GridFluid::Sample(const std::vector<float>& f, double x, double y, double z,
                        bool open) const {
  if (open && (x < 0.5 || x > nx_ + 0.5 || y < 0.5 || y > ny_ + 0.5 || z < 0.5 || z > nz_ + 0.5)) {
    return 0.0f;
  }
  x = std::clamp(x, 0.5, nx_ + 0.5);
  y = std::clamp(y, 0.5, ny_ + 0.5);
  z = std::clamp(z, 0.5, nz_ + 0.5);
  const int i0 = std::min(static_cast<int>(x), nx_), j0 = std::min(static_cast<int>(y), ny_),
            k0 = std::min(static_cast<int>(z), nz_);
  const float s = static_cast<float>(x - i0), t = static_cast<float>(y - j0),
              r = static_cast<float>(z - k0);
  auto lerp = [](float a, float b, float f) { return a + (b - a) * f; };
  const float c00 = lerp(f[Ix(i0, j0, k0)], f[Ix(i0 + 1, j0, k0)], s);
  const float c10 = lerp(f[Ix(i0, j0 + 1, k0)], f[Ix(i0 + 1, j0 + 1, k0)], s);
  const float c01 = lerp(f[Ix(i0, j0, k0 + 1)], f[Ix(i0 + 1, j0, k0 + 1)], s);
  const float c11 = lerp(f[Ix(i0, j0 + 1, k0 + 1)], f[Ix(i0 + 1, j0 + 1, k0 + 1)], s);
  return lerp(lerp(c00, c10, t), lerp(c01, c11, t), r);
}

void GridFluid::Advect(int b, std::vector<float>& dst, const std::vector<float>& src,
                       const Eigen::Vector3d& extra, bool open) const {
  const double dt = params_.dt_sec;
  for (int k = 1; k <= nz_; ++k)
    for (int j = 1; j <= ny_; ++j)
      for (int i = 1; i <= nx_; ++i) {
        const size_t c = Ix(i, j, k);
        const double x = i - dt * (u_[c] + extra.x()) / h_.x();
        const double y = j - dt * (v_[c] + extra.y()) / h_.y();
        const double z = k - dt * (w_[c] + extra.z()) / h_.z();
        dst[c] = Sample(src, x, y, z, open);
      }
  SetBoundary(b, dst);
}

void GridFluid::Project() {
  const double ix2 = 1.0 / (h_.x() * h_.x()), iy2 = 1.0 / (h_.y() * h_.y()),
               iz2 = 1.0 / (h_.z() * h_.z());
  const double diag = 2.0 * (ix2 + iy2 + iz2);
  for (int k = 1; k <= nz_; ++k)
    for (int j = 1; j <= ny_; ++j)
      for (int i = 1; i <= nx_; ++i) {
        div_[Ix(i, j, k)] =
            static_cast<float>((u_[Ix(i + 1, j, k)] - u_[Ix(i - 1, j, k)]) / (2 * h_.x()) +
                               (v_[Ix(i, j + 1, k)] - v_[Ix(i, j - 1, k)]) / (2 * h_.y()) +
                               (w_[Ix(i, j, k + 1)] - w_[Ix(i, j, k - 1)]) / (2 * h_.z()));
      }
  SetBoundary(0, div_);
  std::fill(p_.begin(), p_.end(), 0.0f);
  for (int it = 0; it < params_.jacobi_iterations; ++it) {
    for (int k = 1; k <= nz_; ++k)
      for (int j = 1; j <= ny_; ++j)
        for (int i = 1; i <= nx_; ++i) {
          const double s = (p_[Ix(i + 1, j, k)] + p_[Ix(i - 1, j, k)]) * ix2 +
                           (p_[Ix(i, j + 1, k)] + p_[Ix(i, j - 1, k)]) * iy2 +
                           (p_[Ix(i, j, k + 1)] + p_[Ix(i, j, k - 1)]) * iz2;
          tmp_[Ix(i, j, k)] = static_cast<float>((s - div_[Ix(i, j, k)]) / diag);
        }
    SetBoundary(0, tmp_);
    std::swap(p_, tmp_);
  }
  for (int k = 1; k <= nz_; ++k)
    for (int j = 1; j <= ny_; ++j)
      for (int i = 1; i <= nx_; ++i) {
        const size_t c = Ix(i, j, k);
        u_[c] -= static_cast<float>((p_[Ix(i + 1, j, k)] - p_[Ix(i - 1, j, k)]) / (2 * h_.x()));
        v_[c] -= static_cast<float>((p_[Ix(i, j + 1, k)] - p_[Ix(i, j - 1, k)]) / (2 * h_.y()));
        w_[c] -= static_cast<float>((p_[Ix(i, j, k + 1)] - p_[Ix(i, j, k - 1)]) / (2 * h_.z()));
      }
  SetBoundary(1, u_);
  SetBoundary(2, v_);
  SetBoundary(3, w_);
}

void GridFluid::Step(double weight) {
  const double dt = params_.dt_sec;
  const double t_amb = params_.ambient_temperature_k;
  // sources
  for (size_t e = 0; e < params_.emitters.size(); ++e) {
    const PlumeEmitter& em = params_.emitters[e];
    const std::vector<size_t>& cells = emitter_cells_[e];
    const float add = static_cast<float>(weight * em.rate * dt / (cells.size() * voxel_volume_));
    const float theta = static_cast<float>(weight * (em.temperature_k - t_amb));
    Rng rng(HashKeys(key_, static_cast<uint64_t>(steps_), e));
    const float kick_u =
        static_cast<float>(weight * params_.turbulence_m_s * (2 * rng.UniformD() - 1));
    const float kick_v =
        static_cast<float>(weight * params_.turbulence_m_s * (2 * rng.UniformD() - 1));
    for (size_t c : cells) {
      rho_[c] += add;
      theta_[c] = std::max(theta_[c], theta);
      u_[c] += kick_u;
      v_[c] += kick_v;
    }
  }
  // buoyancy (Fedkiw et al. 2001)
  for (int k = 1; k <= nz_; ++k)
    for (int j = 1; j <= ny_; ++j)
      for (int i = 1; i <= nx_; ++i) {
        const size_t c = Ix(i, j, k);
        w_[c] += static_cast<float>(
            dt * (params_.buoyancy_m_s2 * theta_[c] / t_amb - params_.weight_m_s2 * rho_[c]));
      }
  SetBoundary(1, u_);
  SetBoundary(2, v_);
  SetBoundary(3, w_);
  Project();
  // velocity self-advection (from copies, so all components use the old field)
  {
    std::vector<float> u0 = u_, v0 = v_, w0 = w_;
    std::vector<float> un(u_.size()), vn(v_.size()), wn(w_.size());
    Advect(1, un, u0, Eigen::Vector3d::Zero(), false);
    Advect(2, vn, v0, Eigen::Vector3d::Zero(), false);
    Advect(3, wn, w0, Eigen::Vector3d::Zero(), false);
    u_.swap(un);
    v_.swap(vn);
    w_.swap(wn);
  }
  Project();
  // scalars
  const bool open = wind_.squaredNorm() > 0;
  const double mass_before = TotalMass();
  Advect(0, tmp_, rho_, wind_, open);
  std::swap(rho_, tmp_);
  Advect(0, tmp_, theta_, wind_, open);
  std::swap(theta_, tmp_);
  if (!open) {
    const double mass_after = TotalMass();
    if (mass_after > 0) {
      const float s = static_cast<float>(mass_before / mass_after);
      for (float& r : rho_) r *= s;
    }
  }
  const float decay = static_cast<float>(std::exp(-params_.dissipation_per_s * dt));
  const float cool = static_cast<float>(std::exp(-params_.cooling_per_s * dt));
  for (float& r : rho_) r = std::max(0.0f, r * decay);
  for (float& t : theta_) t *= cool;
  ++steps_;
}

double GridFluid::TotalMass() const {
  double sum = 0;
  for (int k = 1; k <= nz_; ++k)
    for (int j = 1; j <= ny_; ++j)
      for (int i = 1; i <= nx_; ++i) sum += rho_[Ix(i, j, k)];
  return sum * voxel_volume_;
}

Eigen::Vector3d GridFluid::CentreOfMass() const {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  double m = 0;
  for (int k = 0; k < nz_; ++k)
    for (int j = 0; j < ny_; ++j)
      for (int i = 0; i < nx_; ++i) {
        const double d = density(i, j, k);
        sum += d * VoxelCentre(i, j, k);
        m += d;
      }
  return m > 0 ? Eigen::Vector3d(sum / m) : Eigen::Vector3d(0.5 * (region_.min_W + region_.max_W));
}

std::vector<float> GridFluid::DensityGrid() const {
  std::vector<float> out(static_cast<size_t>(nx_) * ny_ * nz_);
  for (int k = 0; k < nz_; ++k)
    for (int j = 0; j < ny_; ++j)
      for (int i = 0; i < nx_; ++i)
        out[(static_cast<size_t>(k) * ny_ + j) * nx_ + i] = density(i, j, k);
  return out;
}

float GridFluid::MaxDensity() const {
  float m = 0;
  for (int k = 0; k < nz_; ++k)
    for (int j = 0; j < ny_; ++j)
      for (int i = 0; i < nx_; ++i) m = std::max(m, density(i, j, k));
  return m;
}

}  // namespace penumbra
