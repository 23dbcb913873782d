#include "penumbra/render/geometry/height_field_sampling.h"

#include <algorithm>
#include <cmath>
#include <memory>
#include <optional>
#include <span>

#include "penumbra/core/error.h"

namespace penumbra {
namespace {

// downward rays from z_top over `points`, closest hits; heights of the hits, nullopt = miss
std::vector<std::optional<double>> CastDownOnce(const RayQuery& query,
                                                const std::vector<Eigen::Vector2d>& points,
                                                double z_top) {
  std::vector<Ray> rays(points.size());
  for (size_t i = 0; i < points.size(); ++i) {
    rays[i].o = Eigen::Vector3f(static_cast<float>(points[i].x()),
                                static_cast<float>(points[i].y()), static_cast<float>(z_top));
    rays[i].d = Eigen::Vector3f(0, 0, -1);
  }
  std::vector<SurfaceHit> hits(rays.size());
  std::unique_ptr<bool[]> did_hit(new bool[rays.size()]);
  query.Intersect(rays, hits, std::span<bool>(did_hit.get(), rays.size()));
  std::vector<std::optional<double>> z(points.size());
  for (size_t i = 0; i < points.size(); ++i)
    if (did_hit[i]) z[i] = z_top - static_cast<double>(hits[i].t);
  return z;
}

// as CastDownOnce, and a ray that misses is cast again 10 and 20 um away: a sample exactly on
// a mesh edge or vertex (terrain meshes often share the grid's spacing) can slip between the
// triangles in Embree's non-watertight default mode
std::vector<std::optional<double>> CastDown(const RayQuery& query,
                                            const std::vector<Eigen::Vector2d>& points,
                                            double z_top) {
  std::vector<std::optional<double>> z = CastDownOnce(query, points, z_top);
  for (const Eigen::Vector2d& offset :
       {Eigen::Vector2d(1e-5, 0.618e-5), Eigen::Vector2d(-1.618e-5, -1e-5)}) {
    std::vector<size_t> missed;
    std::vector<Eigen::Vector2d> again;
    for (size_t i = 0; i < z.size(); ++i)
      if (!z[i]) missed.push_back(i), again.push_back(points[i] + offset);
    if (missed.empty()) break;
    const std::vector<std::optional<double>> retry = CastDownOnce(query, again, z_top);
    for (size_t k = 0; k < missed.size(); ++k) z[missed[k]] = retry[k];
  }
  return z;
}

}  // namespace

double SampledHeightField::HeightAt(double x, double y) const {
  const double u = std::clamp((x - x0) / cell_m, 0.0, static_cast<double>(cols - 1));
  const double v = std::clamp((y - y0) / cell_m, 0.0, static_cast<double>(rows - 1));
  const int c = std::min(static_cast<int>(u), cols - 2),
            r = std::min(static_cast<int>(v), rows - 2);
  const double fu = u - c, fv = v - r;
  const auto at = [&](int rr, int cc) { return z[static_cast<size_t>(rr) * cols + cc]; };
  // the triangles (c, r) (c+1, r) (c+1, r+1) below the diagonal and (c, r) (c+1, r+1) (c, r+1)
  if (fu >= fv)
    return at(r, c) + fu * (at(r, c + 1) - at(r, c)) + fv * (at(r + 1, c + 1) - at(r, c + 1));
  return at(r, c) + fv * (at(r + 1, c) - at(r, c)) + fu * (at(r + 1, c + 1) - at(r + 1, c));
}

SampledHeightField SampleHeightField(const RayQuery& query, const Eigen::Vector2d& lo,
                                     const Eigen::Vector2d& hi, double cell_m, double z_top,
                                     double z_miss) {
  if (!(cell_m > 0)) throw Error("height field cell size must be > 0 m");
  if (!(hi.x() > lo.x() && hi.y() > lo.y()))
    throw Error("height field extent is empty; expected lo < hi in x and y");
  SampledHeightField f;
  f.cell_m = cell_m;
  f.x0 = lo.x();
  f.y0 = lo.y();
  const double cols = std::floor((hi.x() - lo.x()) / cell_m + 1e-9) + 1;
  const double rows = std::floor((hi.y() - lo.y()) / cell_m + 1e-9) + 1;
  if (cols > 4096 || rows > 4096)
    throw Error("height field of " + std::to_string(static_cast<long>(cols)) + " x " +
                std::to_string(static_cast<long>(rows)) +
                " samples is too large; expected at most 4096 x 4096 (use a larger cell)");
  f.cols = std::max(2, static_cast<int>(cols));
  f.rows = std::max(2, static_cast<int>(rows));
  // one batch per row: neighbouring rays along x are coherent
  f.z.resize(static_cast<size_t>(f.rows) * f.cols);
  std::vector<Eigen::Vector2d> row(f.cols);
  for (int r = 0; r < f.rows; ++r) {
    for (int c = 0; c < f.cols; ++c) row[c] = {f.x0 + c * cell_m, f.y0 + r * cell_m};
    const std::vector<std::optional<double>> z = CastDown(query, row, z_top);
    for (int c = 0; c < f.cols; ++c) {
      f.z[static_cast<size_t>(r) * f.cols + c] = z[c].value_or(z_miss);
      if (!z[c]) ++f.misses;
    }
  }
  return f;
}

HeightFieldError ErrorAtCellCentres(const RayQuery& query, const SampledHeightField& field,
                                    double z_top) {
  HeightFieldError e;
  double sum = 0;
  std::vector<Eigen::Vector2d> row(field.cols - 1);
  for (int r = 0; r + 1 < field.rows; ++r) {
    for (int c = 0; c + 1 < field.cols; ++c)
      row[c] = {field.x0 + (c + 0.5) * field.cell_m, field.y0 + (r + 0.5) * field.cell_m};
    const std::vector<std::optional<double>> z = CastDown(query, row, z_top);
    for (int c = 0; c + 1 < field.cols; ++c) {
      if (!z[c]) continue;
      const double d = std::abs(field.HeightAt(row[c].x(), row[c].y()) - *z[c]);
      e.max_m = std::max(e.max_m, d);
      sum += d;
      ++e.cells;
    }
  }
  e.mean_m = e.cells > 0 ? sum / e.cells : 0;
  return e;
}

}  // namespace penumbra
