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

void GridFluid::AdvanceTo(double t_sec, const std::function<double(double)>& emission_weight_at) {
  const double dt = params_.dt_sec;
  const int target = static_cast<int>(std::floor(t_sec / dt + 1e-9));
  if (target < steps_) Reset();
  while (steps_ < target) Step(emission_weight_at(steps_ * dt));
}

GridMedium RegionGridMedium(const BoxRegion& r, int nx, int ny, int nz) {
  GridMedium g;
  g.X_WG = Pose::Identity();
  g.X_WG.translation() = 0.5 * (r.min_W + r.max_W);
  g.half_extents_m = 0.5 * (r.max_W - r.min_W);
  g.nx = nx;
  g.ny = ny;
  g.nz = nz;
  return g;
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

// advects `count` fields along one backtrace per voxel: the semi-Lagrangian step of Stam
// 1999 with trilinear interpolation at grid coordinates where interior voxel centres sit at
// 1..n. closed: the departure point is clamped to [0.5, n + 0.5]; open: outside that range
// the value is 0 (clean air flows in).
void GridFluid::Advect(int count, const int* b, std::vector<float>* const* dst,
                       const std::vector<float>* const* src, const Eigen::Vector3d& extra,
                       bool open) const {
  const double cx = params_.dt_sec / h_.x(), cy = params_.dt_sec / h_.y(),
               cz = params_.dt_sec / h_.z();
  const size_t sy = nx_ + 2, sz = static_cast<size_t>(nx_ + 2) * (ny_ + 2);
  for (int k = 1; k <= nz_; ++k)
    for (int j = 1; j <= ny_; ++j)
      for (int i = 1; i <= nx_; ++i) {
        const size_t c = Ix(i, j, k);
        double x = i - cx * (u_[c] + extra.x());
        double y = j - cy * (v_[c] + extra.y());
        double z = k - cz * (w_[c] + extra.z());
        if (open &&
            (x < 0.5 || x > nx_ + 0.5 || y < 0.5 || y > ny_ + 0.5 || z < 0.5 || z > nz_ + 0.5)) {
          for (int f = 0; f < count; ++f) (*dst[f])[c] = 0.0f;
          continue;
        }
        x = std::clamp(x, 0.5, nx_ + 0.5);
        y = std::clamp(y, 0.5, ny_ + 0.5);
        z = std::clamp(z, 0.5, nz_ + 0.5);
        const int i0 = std::min(static_cast<int>(x), nx_), j0 = std::min(static_cast<int>(y), ny_),
                  k0 = std::min(static_cast<int>(z), nz_);
        const float s1 = static_cast<float>(x - i0), t1 = static_cast<float>(y - j0),
                    r1 = static_cast<float>(z - k0);
        const float s0 = 1 - s1, t0 = 1 - t1, r0 = 1 - r1;
        const size_t o = Ix(i0, j0, k0);
        for (int f = 0; f < count; ++f) {
          const float* q = src[f]->data() + o;
          const float lo = t0 * (s0 * q[0] + s1 * q[1]) + t1 * (s0 * q[sy] + s1 * q[sy + 1]);
          const float hi =
              t0 * (s0 * q[sz] + s1 * q[sz + 1]) + t1 * (s0 * q[sz + sy] + s1 * q[sz + sy + 1]);
          (*dst[f])[c] = r0 * lo + r1 * hi;
        }
      }
  for (int f = 0; f < count; ++f) SetBoundary(b[f], *dst[f]);
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
  // Jacobi sweeps over rows with fixed strides (x, y, z neighbours at 1, sy, sz)
  const float fx = static_cast<float>(ix2 / diag), fy = static_cast<float>(iy2 / diag),
              fz = static_cast<float>(iz2 / diag), fd = static_cast<float>(1.0 / diag);
  const ptrdiff_t sy = nx_ + 2, sz = static_cast<ptrdiff_t>(nx_ + 2) * (ny_ + 2);
  for (int it = 0; it < params_.jacobi_iterations; ++it) {
    for (int k = 1; k <= nz_; ++k)
      for (int j = 1; j <= ny_; ++j) {
        const size_t row = Ix(1, j, k);
        const float* p = p_.data() + row;
        const float* d = div_.data() + row;
        float* out = tmp_.data() + row;
        for (int i = 0; i < nx_; ++i) {
          out[i] = (p[i + 1] + p[i - 1]) * fx + (p[i + sy] + p[i - sy]) * fy +
                   (p[i + sz] + p[i - sz]) * fz - d[i] * fd;
        }
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
  // velocity self-advection: all three components along the same backtrace of the old field
  {
    std::vector<float> un(u_.size()), vn(v_.size()), wn(w_.size());
    const int b[3] = {1, 2, 3};
    std::vector<float>* dst[3] = {&un, &vn, &wn};
    const std::vector<float>* src[3] = {&u_, &v_, &w_};
    Advect(3, b, dst, src, Eigen::Vector3d::Zero(), false);
    u_.swap(un);
    v_.swap(vn);
    w_.swap(wn);
  }
  Project();
  // scalars, moved by velocity + wind
  const bool open = wind_.squaredNorm() > 0;
  const double mass_before = TotalMass();
  {
    std::vector<float> rn(rho_.size());
    const int b[2] = {0, 0};
    std::vector<float>* dst[2] = {&rn, &tmp_};
    const std::vector<float>* src[2] = {&rho_, &theta_};
    Advect(2, b, dst, src, wind_, open);
    rho_.swap(rn);
    std::swap(theta_, tmp_);
  }
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
