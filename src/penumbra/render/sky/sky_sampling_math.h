#pragma once
// SkyModel's importance sampling of the sky (render/sky/sky_model.h: Sample and Pdf) over plain
// data, shared by the CPU's SkyModel and the CUDA backend's path kernels
// (render/transport/path_trace.h). the tables: a piecewise-constant 2d distribution over cells of
// the sphere, rows in theta (from +z) and columns in phi (from +x towards +y), with density
// proportional to the sky's luminance times sin(theta) (Pharr, Jakob, Humphreys, "Physically
// Based Rendering", 3rd ed., sec. 13.3.1 and 14.2.4); each 1d distribution has a guide table
// (Chen and Asau 1974) to start its search next to its answer, and samples keep
// kSkyCellMargin of a cell away from its edges so that float rounding of the direction never
// moves SkyPdf into a neighbouring cell (densities scale to match).

#include <cstdint>

#include "penumbra/core/host_device.h"

namespace penumbra {

/// the fraction of a cell a sample keeps away from each of its edges.
inline constexpr float kSkyCellMargin = 1e-4f;

/// one piecewise-constant 1d distribution on [0, 1] of n cells: densities pdf[n] (on [0, 1]),
/// cdf[n + 1] (cdf[n] = 1) and guide[n] (the cell holding u = k / n).
struct SkyDistributionPod {
  const float* pdf = nullptr;
  const float* cdf = nullptr;
  const int32_t* guide = nullptr;
  int32_t n = 0;
};

/// SkyModel's sampling tables as plain data (SkyModel::sampling_pod()): the marginal over rows
/// and one conditional over columns per row, all pointing into arrays the SkyModel owns (or
/// their device copies).
struct SkySamplingPod {
  int32_t rows = 0, cols = 0;
  SkyDistributionPod marginal;
  /// rows x cols densities, rows x (cols + 1) cdf values and rows x cols guide entries.
  const float* cond_pdf = nullptr;
  const float* cond_cdf = nullptr;
  const int32_t* cond_guide = nullptr;
  /// the conditional distribution of row r.
  PB_HOST_DEVICE SkyDistributionPod Conditional(int r) const {
    SkyDistributionPod d;
    d.pdf = cond_pdf + static_cast<int64_t>(r) * cols;
    d.cdf = cond_cdf + static_cast<int64_t>(r) * (cols + 1);
    d.guide = cond_guide + static_cast<int64_t>(r) * cols;
    d.n = cols;
    return d;
  }
};

/// the density on [0, 1] in cell i of distribution d (scaled for the cell margin).
PB_HOST_DEVICE inline float SkyCellPdf(const SkyDistributionPod& d, int i) {
  return d.pdf[i] / (1 - 2 * kSkyCellMargin);
}

/// maps u in [0, 1) to x in [0, 1) by distribution d; writes the density at x and the cell.
PB_HOST_DEVICE inline float SkyDistributionSample(const SkyDistributionPod& d, float u, float* pdf,
                                                  int* cell) {
  const int n = d.n;
  // the cell with cdf[i] <= u < cdf[i + 1], searched forward from the guide entry.
  int g = static_cast<int>(u * n);
  g = g < 0 ? 0 : (n - 1 < g ? n - 1 : g);
  int i = d.guide[g];
  while (i < n - 1 && d.cdf[i + 1] <= u) ++i;
  // skip zero-width cells the search may land on.
  while (i < n - 1 && d.pdf[i] <= 0) ++i;
  const float width = d.cdf[i + 1] - d.cdf[i];
  float du = width > 0 ? (u - d.cdf[i]) / width : 0.5f;
  du = kSkyCellMargin + (du < 0.0f ? 0.0f : (1.0f < du ? 1.0f : du)) * (1 - 2 * kSkyCellMargin);
  *pdf = SkyCellPdf(d, i);
  *cell = i;
  return (i + du) / n;
}

/// SkyModel::Sample: a unit direction dir (x, y, z) with density roughly proportional to the
/// sky's radiance from two uniform numbers in [0, 1), and its solid-angle density *pdf.
PB_HOST_DEVICE inline void SkySampleDirection(const SkySamplingPod& m, float u1, float u2,
                                              float* pdf, float dir[3]) {
  constexpr float kPiF = 3.14159265358979323846f;
  float pdf_v = 0, pdf_u = 0;
  int row = 0, col = 0;
  const float v = SkyDistributionSample(m.marginal, u2, &pdf_v, &row);
  const float u = SkyDistributionSample(m.Conditional(row), u1, &pdf_u, &col);
  const float theta = v * kPiF, phi = u * 2 * kPiF;
  const float sin_theta = sinf(theta);
  *pdf = sin_theta > 0 ? pdf_v * pdf_u / (2 * kPiF * kPiF * sin_theta) : 0.0f;
  dir[0] = sin_theta * cosf(phi);
  dir[1] = sin_theta * sinf(phi);
  dir[2] = cosf(theta);
}

/// SkyModel::Pdf: the solid-angle density with which SkySampleDirection returns the direction
/// (x, y, z) (theta and sin(theta) from atan2 and hypot, accurate near the poles).
PB_HOST_DEVICE inline float SkyDirectionPdf(const SkySamplingPod& m, float x, float y, float z) {
  constexpr float kPiF = 3.14159265358979323846f;
  const float rho = hypotf(x, y);
  const float len = hypotf(rho, z);
  if (!(len > 0) || !(rho > 0)) return 0.0f;
  const float theta = atan2f(rho, z);
  const float sin_theta = rho / len;
  float phi = atan2f(y, x);
  if (phi < 0) phi += 2 * kPiF;
  int row = static_cast<int>(theta / kPiF * m.rows);
  row = row < 0 ? 0 : (m.rows - 1 < row ? m.rows - 1 : row);
  int col = static_cast<int>(phi / (2 * kPiF) * m.cols);
  col = col < 0 ? 0 : (m.cols - 1 < col ? m.cols - 1 : col);
  return SkyCellPdf(m.marginal, row) * SkyCellPdf(m.Conditional(row), col) /
         (2 * kPiF * kPiF * sin_theta);
}

}  // namespace penumbra
