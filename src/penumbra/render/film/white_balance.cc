#include "penumbra/render/film/white_balance.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "penumbra/render/sky/sky_model.h"

namespace penumbra {
namespace {

constexpr float kMaxWbGain = 16.0f;

float Rec709Luminance(const Eigen::Vector3f& c) {
  return 0.2126f * c.x() + 0.7152f * c.y() + 0.0722f * c.z();
}

}  // namespace

Eigen::Vector3f WhiteBalanceGains(const Eigen::Vector3f& w) {
  if (!w.allFinite() || !(w.minCoeff() > 0)) return Eigen::Vector3f::Ones();
  if (w.x() == w.y() && w.y() == w.z()) return Eigen::Vector3f::Ones();  // already neutral
  const float y = Rec709Luminance(w);
  Eigen::Vector3f g;
  for (int c = 0; c < 3; ++c) g[c] = std::clamp(y / w[c], 1.0f / kMaxWbGain, kMaxWbGain);
  return g;
}

Eigen::Vector3f PlanckianWhiteRgb(double kelvin) {
  const double t = std::clamp(kelvin, WhiteBalance::kMinKelvin, WhiteBalance::kMaxKelvin);
  const double t1 = 1e3 / t, t2 = t1 * t1, t3 = t2 * t1;  // in units of 1000 K
  // Kang et al. 2002, eqs. (1) and (2): the Planckian locus as cubics in 1/T and x.
  const double x = t <= 4000 ? -0.2661239 * t3 - 0.2343589 * t2 + 0.8776956 * t1 + 0.179910
                             : -3.0258469 * t3 + 2.1070379 * t2 + 0.2226347 * t1 + 0.240390;
  const double x2 = x * x, x3 = x2 * x;
  double y;
  if (t <= 2222) {
    y = -1.1063814 * x3 - 1.34811020 * x2 + 2.18555832 * x - 0.20219683;
  } else if (t <= 4000) {
    y = -0.9549476 * x3 - 1.37418593 * x2 + 2.09137015 * x - 0.16748867;
  } else {
    y = 3.0817580 * x3 - 5.87338670 * x2 + 3.75112997 * x - 0.37001483;
  }
  const double X = x / y, Y = 1.0, Z = (1.0 - x - y) / y;
  // XYZ -> linear sRGB (IEC 61966-2-1).
  Eigen::Vector3f rgb(static_cast<float>(3.2406 * X - 1.5372 * Y - 0.4986 * Z),
                      static_cast<float>(-0.9689 * X + 1.8758 * Y + 0.0415 * Z),
                      static_cast<float>(0.0557 * X - 0.2040 * Y + 1.0570 * Z));
  rgb = rgb.cwiseMax(1e-3f);
  return rgb / Rec709Luminance(rgb);
}

Eigen::Vector3f GrayWorldWhite(const ImageF& radiance) {
  if (radiance.empty() || radiance.channels != 3) return Eigen::Vector3f::Zero();
  const int w = radiance.width, h = radiance.height;
  std::vector<Eigen::Vector3d> rows(h, Eigen::Vector3d::Zero());
  std::vector<int64_t> counts(h, 0);
  for (int v = 0; v < h; ++v) {
    const float* p = radiance.at(0, v);
    for (int u = 0; u < w; ++u, p += 3) {
      if (!(std::isfinite(p[0]) && std::isfinite(p[1]) && std::isfinite(p[2]))) continue;
      rows[v] += Eigen::Vector3d(p[0], p[1], p[2]);
      ++counts[v];
    }
  }
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  int64_t n = 0;
  for (int v = 0; v < h; ++v) {
    sum += rows[v];
    n += counts[v];
  }
  return n > 0 ? Eigen::Vector3f((sum / static_cast<double>(n)).cast<float>())
               : Eigen::Vector3f::Zero();
}

Eigen::Vector3f DaylightWhite(const SceneDescription& scene) {
  Eigen::Vector3f e = scene.sky.type == Sky::Type::kDaylight
                          ? SkyModel(scene.sky).Irradiance(Eigen::Vector3f(0, 0, 1))
                          : Eigen::Vector3f::Zero();
  for (const Light& l : scene.lights) {
    if (!l.active || l.type != Light::Type::kDirectional || l.body != 0) continue;
    const double cos_z = std::max(0.0, -l.direction_B.normalized().z());
    e += l.color * static_cast<float>(l.intensity * cos_z);
  }
  return e;
}

Eigen::Vector3f GainsForFrame(const WhiteBalance& wb, const Eigen::Vector3f& daylight_white,
                              const ImageF& radiance) {
  switch (wb.mode) {
    case WhiteBalance::Mode::kNone:
      return Eigen::Vector3f::Ones();
    case WhiteBalance::Mode::kAuto:
      return WhiteBalanceGains(GrayWorldWhite(radiance));
    case WhiteBalance::Mode::kDaylight:
      return WhiteBalanceGains(daylight_white);
    case WhiteBalance::Mode::kKelvin:
      return WhiteBalanceGains(PlanckianWhiteRgb(wb.kelvin));
  }
  return Eigen::Vector3f::Ones();
}

}  // namespace penumbra
