#include "penumbra/render/sky/sky_model.h"

#include <algorithm>
#include <cmath>
#include <memory>
#include <numbers>
#include <string>
#include <vector>

#include "penumbra/core/error.h"
#include "penumbra/render/sky/sky_eval_math.h"
#include "penumbra/render/sky/sky_math.h"
#include "penumbra/render/sky/sky_sampling_math.h"
#include "penumbra/scene/texture_image.h"

namespace penumbra {
namespace {

// a diffuse ground of this albedo is seen below the horizon of a daylight sky.
constexpr double kGroundAlbedo = 0.2;

// sampling table: cells over the whole sphere in (theta from +z, phi from +x towards +y).
constexpr int kSampleRows = 128;  // theta in [0, pi]
constexpr int kSampleCols = 256;  // phi in [0, 2 pi)
// irradiance quadrature: cells over the upper hemisphere only (the ground is analytic).
constexpr int kQuadRows = 64;  // theta in [0, pi / 2]
constexpr int kQuadCols = 128;
// irradiance table: nodes over directions on an octahedral map (Praun and
// Hoppe, "Spherical parametrization and remeshing", SIGGRAPH 2003; Cigolle et al., "A survey
// of efficient representations for independent unit vectors", JCGT 2014), bilinear between
// nodes: looking up a direction needs no trigonometry.
constexpr int kIrrSide = kSkyIrrSide;

// Rec. 709 / sRGB luminance weights (row Y of the RGB -> XYZ matrix, D65 white), IEC 61966-2-1.
double Luminance(const Eigen::Vector3d& rgb) {
  return 0.2126729 * rgb.x() + 0.7151522 * rgb.y() + 0.0721750 * rgb.z();
}

Eigen::Vector3d DirectionFromAngles(double theta, double phi) {
  const double s = std::sin(theta);
  return {s * std::cos(phi), s * std::sin(phi), std::cos(theta)};
}

// piecewise-constant 1d distribution on [0, 1] (Pharr, Jakob, Humphreys, "Physically Based
// Rendering", 3rd ed., sec. 13.3.1). built in double, stored in float (compact tables).
class Distribution1D {
 public:
  explicit Distribution1D(std::vector<double> f) : pdf_(f.size()), cdf_(f.size() + 1) {
    const int n = static_cast<int>(f.size());
    std::vector<double> cdf(n + 1, 0.0);
    for (int i = 0; i < n; ++i) cdf[i + 1] = cdf[i] + f[i] / n;
    integral_ = cdf[n];
    if (!(integral_ > 0)) {
      // a zero function samples uniformly.
      std::fill(f.begin(), f.end(), 1.0);
      for (int i = 0; i <= n; ++i) cdf[i] = static_cast<double>(i) / n;
      integral_ = 1;
    } else {
      for (int i = 1; i <= n; ++i) cdf[i] /= integral_;
    }
    for (int i = 0; i < n; ++i) pdf_[i] = static_cast<float>(f[i] / integral_);
    for (int i = 0; i <= n; ++i) cdf_[i] = static_cast<float>(cdf[i]);
    cdf_[n] = 1.0f;
    // guide table (Chen and Asau 1974): the cell holding u = k / n, so that a search starts
    // next to its answer.
    guide_.resize(n);
    int i = 0;
    for (int k = 0; k < n; ++k) {
      const float u = static_cast<float>(k) / n;
      while (i < n - 1 && cdf_[i + 1] <= u) ++i;
      guide_[k] = i;
    }
  }

  int count() const { return static_cast<int>(pdf_.size()); }
  double integral() const { return integral_; }
  /// densities, cdf and guide table as SkyDistributionPod takes them (sampled by the shared
  /// SkyDistributionSample, render/sky/sky_sampling_math.h).
  const std::vector<float>& pdf() const { return pdf_; }
  const std::vector<float>& cdf() const { return cdf_; }
  const std::vector<int>& guide() const { return guide_; }

 private:
  std::vector<float> pdf_;
  std::vector<float> cdf_;
  std::vector<int> guide_;
  double integral_ = 0;
};

// the unit direction of octahedral coordinates (s, t) in [0, 1]^2 (the inverse of
// SkyIrradiance's encoding, render/sky/sky_eval_math.h).
Eigen::Vector3d OctDecode(double s, double t) {
  double x = 2 * s - 1, y = 2 * t - 1;
  const double z = 1 - std::abs(x) - std::abs(y);
  if (z < 0) {
    const double fx = (1 - std::abs(y)) * (x >= 0 ? 1.0 : -1.0);
    const double fy = (1 - std::abs(x)) * (y >= 0 ? 1.0 : -1.0);
    x = fx, y = fy;
  }
  return Eigen::Vector3d(x, y, z).normalized();
}

}  // namespace

struct SkyModel::Impl {
  Sky::Type type = Sky::Type::kUniform;
  // the uniform radiance or the daylight model's state, the irradiance table and the skybox
  // as the shared functions take them (render/sky/sky_eval_math.h); its pointers into this Impl.
  SkyModelPod pod;
  double theta_sun = 0;

  // sampling: marginal over rows (theta), conditionals per row over phi, flattened for the
  // shared functions (render/sky/sky_sampling_math.h) and pointed to by `sampling`.
  std::vector<float> marginal_pdf, marginal_cdf, cond_pdf, cond_cdf;
  std::vector<int32_t> marginal_guide, cond_guide;
  SkySamplingPod sampling;
  // irradiance table (kIrrSide x kIrrSide octahedral nodes), per channel.
  std::vector<Eigen::Vector3f> irradiance;

  Eigen::Vector3d Upper(const Eigen::Vector3d& d) const {
    Eigen::Vector3d out;
    SkyUpperRadiance(pod, d.data(), out.data());
    return out;
  }
  Eigen::Vector3d Eval(const Eigen::Vector3d& d) const {
    Eigen::Vector3d out;
    SkyRadianceD(pod, d.data(), out.data());
    return out;
  }
  Eigen::Vector3d ground() const { return {pod.ground[0], pod.ground[1], pod.ground[2]}; }
  Eigen::Vector3d uniform() const { return {pod.uniform[0], pod.uniform[1], pod.uniform[2]}; }
  // MJCF skybox seen by camera and mirror rays (null: none), and the radiance of a white texel.
  SkyboxBackground skybox;
  double skybox_white = 0;

  void SetUpDaylight(const Sky& sky);
  void BuildSampling();
  void BuildIrradiance();
};

void SkyModel::Impl::BuildSampling() {
  // luminance x sin(theta) at cell centres: pbrt's environment-map sampling (sec. 14.2.4).
  std::vector<double> lum(static_cast<size_t>(kSampleRows) * kSampleCols);
  double max_lum = 0;
  for (int r = 0; r < kSampleRows; ++r) {
    const double theta = (r + 0.5) * std::numbers::pi / kSampleRows;
    for (int c = 0; c < kSampleCols; ++c) {
      const double phi = (c + 0.5) * 2 * std::numbers::pi / kSampleCols;
      const double l = std::max(Luminance(Eval(DirectionFromAngles(theta, phi))), 0.0);
      lum[static_cast<size_t>(r) * kSampleCols + c] = l;
      max_lum = std::max(max_lum, l);
    }
  }
  // a black sky samples the sphere (almost) uniformly so that Sample/Pdf stay valid.
  if (!(max_lum > 0)) std::fill(lum.begin(), lum.end(), 1.0);
  std::vector<double> row_integrals(kSampleRows);
  for (int r = 0; r < kSampleRows; ++r) {
    const double sin_theta = std::sin((r + 0.5) * std::numbers::pi / kSampleRows);
    std::vector<double> f(kSampleCols);
    double sum = 0;
    for (int c = 0; c < kSampleCols; ++c) {
      f[c] = lum[static_cast<size_t>(r) * kSampleCols + c] * sin_theta;
      sum += f[c];
    }
    row_integrals[r] = sum / kSampleCols;
    const Distribution1D conditional(std::move(f));
    cond_pdf.insert(cond_pdf.end(), conditional.pdf().begin(), conditional.pdf().end());
    cond_cdf.insert(cond_cdf.end(), conditional.cdf().begin(), conditional.cdf().end());
    cond_guide.insert(cond_guide.end(), conditional.guide().begin(), conditional.guide().end());
  }
  const Distribution1D marginal(std::move(row_integrals));
  marginal_pdf = marginal.pdf();
  marginal_cdf = marginal.cdf();
  marginal_guide.assign(marginal.guide().begin(), marginal.guide().end());
  sampling.rows = kSampleRows;
  sampling.cols = kSampleCols;
  sampling.marginal.pdf = marginal_pdf.data();
  sampling.marginal.cdf = marginal_cdf.data();
  sampling.marginal.guide = marginal_guide.data();
  sampling.marginal.n = kSampleRows;
  sampling.cond_pdf = cond_pdf.data();
  sampling.cond_cdf = cond_cdf.data();
  sampling.cond_guide = cond_guide.data();
}

// irradiance E(n) = integral of L(w) max(0, n.w) dw, tabulated over normals. the upper
// hemisphere is integrated by the midpoint rule on kQuadRows x kQuadCols cells; the ground
// (constant radiance G over the lower hemisphere) contributes G pi (1 - n_z) / 2 exactly.
void SkyModel::Impl::BuildIrradiance() {
  const int cells = kQuadRows * kQuadCols;
  std::vector<float> dx(cells), dy(cells), dz(cells), lr(cells), lg(cells), lb(cells);
  const double dphi = 2 * std::numbers::pi / kQuadCols;
  for (int r = 0; r < kQuadRows; ++r) {
    const double t0 = r * 0.5 * std::numbers::pi / kQuadRows,
                 t1 = (r + 1) * 0.5 * std::numbers::pi / kQuadRows;
    const double theta = 0.5 * (t0 + t1);
    const double d_omega = dphi * (std::cos(t0) - std::cos(t1));
    for (int c = 0; c < kQuadCols; ++c) {
      const Eigen::Vector3d d = DirectionFromAngles(theta, (c + 0.5) * dphi);
      const Eigen::Vector3d l = Eval(d) * d_omega;
      const int i = r * kQuadCols + c;
      dx[i] = static_cast<float>(d.x());
      dy[i] = static_cast<float>(d.y());
      dz[i] = static_cast<float>(d.z());
      lr[i] = static_cast<float>(l.x());
      lg[i] = static_cast<float>(l.y());
      lb[i] = static_cast<float>(l.z());
    }
  }
  const Eigen::Vector3d g = type == Sky::Type::kUniform ? uniform() : ground();
  irradiance.resize(static_cast<size_t>(kIrrSide) * kIrrSide);
  for (int r = 0; r < kIrrSide; ++r) {
    for (int c = 0; c < kIrrSide; ++c) {
      const Eigen::Vector3d n = OctDecode(static_cast<double>(c) / (kIrrSide - 1),
                                          static_cast<double>(r) / (kIrrSide - 1));
      const float nx = static_cast<float>(n.x()), ny = static_cast<float>(n.y()),
                  nz = static_cast<float>(n.z());
      double er = 0, eg = 0, eb = 0;
      for (int q = 0; q < kQuadRows; ++q) {
        float sr = 0, sg = 0, sb = 0;
        for (int k = q * kQuadCols; k < (q + 1) * kQuadCols; ++k) {
          const float cosine = std::max(0.0f, nx * dx[k] + ny * dy[k] + nz * dz[k]);
          sr += cosine * lr[k];
          sg += cosine * lg[k];
          sb += cosine * lb[k];
        }
        er += sr;
        eg += sg;
        eb += sb;
      }
      const Eigen::Vector3d e =
          Eigen::Vector3d(er, eg, eb) + g * (std::numbers::pi * 0.5 * (1 - n.z()));
      irradiance[static_cast<size_t>(r) * kIrrSide + c] = e.cast<float>();
    }
  }
}

// the daylight model's state for `sky` (a daylight sky): validation, Perez coefficients, zenith
// values and the ground below the horizon.
void SkyModel::Impl::SetUpDaylight(const Sky& sky) {
  const double t = sky.turbidity;
  if (!(t >= 1.7 && t <= 10))
    throw ConfigError("", 0, "sky.turbidity",
                      "got " + std::to_string(t) + "; expected a turbidity in [1.7, 10]");
  const double norm = sky.sun_direction_W.norm();
  if (!(norm > 1e-9) || !sky.sun_direction_W.allFinite())
    throw ConfigError("", 0, "sky.sun_direction_W", "expected a non-zero finite direction");
  if (!(sky.zenith_luminance >= 0) || !std::isfinite(sky.zenith_luminance))
    throw ConfigError("", 0, "sky.zenith_luminance", "expected a finite luminance >= 0 cd/m^2");
  // the model's fits hold for the sun above the horizon; a lower sun is moved up to it.
  Eigen::Vector3d sun = sky.sun_direction_W / norm;
  if (sun.z() < 0) {
    sun.z() = 0;
    sun = sun.norm() > 1e-9 ? Eigen::Vector3d(sun.normalized()) : Eigen::Vector3d(1, 0, 0);
  }
  for (int k = 0; k < 3; ++k) pod.sun[k] = sun[k];
  const double ts = std::acos(std::clamp(sun.z(), 0.0, 1.0));
  this->theta_sun = ts;
  // Perez coefficients as linear functions of turbidity (Preetham et al. 1999, appendix A.2).
  pod.perez_y = {0.1787 * t - 1.4630, -0.3554 * t + 0.4275, -0.0227 * t + 5.3251,
                 0.1206 * t - 2.5771, -0.0670 * t + 0.3703};
  pod.perez_x = {-0.0193 * t - 0.2592, -0.0665 * t + 0.0008, -0.0004 * t + 0.2125,
                 -0.0641 * t - 0.8989, -0.0033 * t + 0.0452};
  pod.perez_yc = {-0.0167 * t - 0.2608, -0.0950 * t + 0.0092, -0.0079 * t + 0.2102,
                  -0.0441 * t - 1.6537, -0.0109 * t + 0.0529};
  // zenith chromaticity (appendix A.2): [T^2 T 1] M [ts^3 ts^2 ts 1]^T.
  const double t_vec[3] = {t * t, t, 1};
  const double s_vec[4] = {ts * ts * ts, ts * ts, ts, 1};
  static constexpr double kMx[3][4] = {{0.00166, -0.00375, 0.00209, 0},
                                       {-0.02903, 0.06377, -0.03202, 0.00394},
                                       {0.11693, -0.21196, 0.06052, 0.25886}};
  static constexpr double kMy[3][4] = {{0.00275, -0.00610, 0.00317, 0},
                                       {-0.04214, 0.08970, -0.04153, 0.00516},
                                       {0.15346, -0.26756, 0.06670, 0.26688}};
  double xz = 0, yz = 0;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 4; ++j) {
      xz += t_vec[i] * kMx[i][j] * s_vec[j];
      yz += t_vec[i] * kMy[i][j] * s_vec[j];
    }
  // the zenith luminance of the model, Yz = (4.0453 T - 4.9710) tan(chi) - 0.2155 T + 2.4192
  // kcd/m^2, is replaced by the configured Sky::zenith_luminance (the overall scale of the
  // model's luminance is only a fit; its angular distribution is kept).
  const double cos_ts = std::cos(ts);
  pod.y_scale = sky.zenith_luminance / pod.perez_y(1.0, ts, cos_ts);
  pod.x_scale = xz / pod.perez_x(1.0, ts, cos_ts);
  pod.yc_scale = yz / pod.perez_yc(1.0, ts, cos_ts);
  // below the horizon: a Lambertian ground of albedo kGroundAlbedo lit by this sky alone
  // (the sun is a separate Light; its bounce is not included), radiance
  // G = albedo / pi * E_up, with E_up the sky irradiance on an upward-facing surface.
  // constant over the lower hemisphere, it darkens the horizon value as a ground bounce.
  double e_up[3] = {0, 0, 0};
  const double dphi = 2 * std::numbers::pi / kSampleCols;
  for (int r = 0; r < kSampleRows; ++r) {
    const double t0 = r * 0.5 * std::numbers::pi / kSampleRows,
                 t1 = (r + 1) * 0.5 * std::numbers::pi / kSampleRows;
    const double theta = 0.5 * (t0 + t1);
    // integral of cos(theta) d omega over the cell.
    const double w = dphi * 0.5 * (std::sin(t1) * std::sin(t1) - std::sin(t0) * std::sin(t0));
    for (int c = 0; c < kSampleCols; ++c) {
      const Eigen::Vector3d l = this->Upper(DirectionFromAngles(theta, (c + 0.5) * dphi));
      for (int k = 0; k < 3; ++k) e_up[k] += l[k] * w;
    }
  }
  const Eigen::Vector3d ground =
      Eigen::Vector3d(e_up[0], e_up[1], e_up[2]) * (kGroundAlbedo / std::numbers::pi);
  for (int k = 0; k < 3; ++k) pod.ground[k] = ground[k];
}

SkyboxBackground MjcfSkyboxOf(const SceneDescription& scene) {
  SkyboxBackground out;
  for (const Texture& t : scene.textures) {
    if (t.kind == Texture::Kind::kSkybox && t.image != nullptr) {
      out.image = t.image;
      break;
    }
  }
  if (out.image == nullptr) return out;
  double e = 0;
  for (const Light& l : scene.lights) {
    if (l.type != Light::Type::kDirectional || !l.active || l.body != 0 || l.mjcf_light >= 0)
      continue;
    const double n = l.direction_B.norm();
    const double cosine = n > 0 ? -l.direction_B.z() / n : 0.0;
    if (cosine > 0) e += static_cast<double>(l.intensity) * cosine;
  }
  out.sun_horizontal_lux = static_cast<float>(e);
  return out;
}

SkyModel::SkyModel(const Sky& sky, SkyboxBackground skybox) {
  auto impl = std::make_shared<Impl>();
  impl->type = sky.type;
  impl->pod.daylight = sky.type == Sky::Type::kUniform ? 0 : 1;
  if (sky.type == Sky::Type::kUniform) {
    if (!sky.radiance.allFinite() || sky.radiance.minCoeff() < 0)
      throw ConfigError("", 0, "sky.radiance",
                        "uniform sky radiance must be finite and >= 0 per channel");
    for (int k = 0; k < 3; ++k) impl->pod.uniform[k] = static_cast<double>(sky.radiance[k]);
  } else {
    impl->SetUpDaylight(sky);
  }
  if (skybox.image != nullptr) {
    if (skybox.image->faces() != 6 || skybox.image->level(0).width != skybox.image->level(0).height)
      throw ConfigError("", 0, "skybox",
                        "expected a skybox texture of six square faces (MuJoCo's cube layout)");
    if (!(skybox.sun_horizontal_lux >= 0) || !std::isfinite(skybox.sun_horizontal_lux))
      throw ConfigError("", 0, "skybox.sun_horizontal_lux", "expected a finite value >= 0 lux");
  }
  impl->skybox = std::move(skybox);
  impl->BuildSampling();
  impl->BuildIrradiance();
  impl->pod.irradiance = impl->irradiance.data()->data();
  if (impl->skybox.image != nullptr) {
    // a white Lambertian surface facing up under the sky and the sun.
    Eigen::Vector3f e;
    SkyIrradiance(impl->pod, 0.0f, 0.0f, 1.0f, e.data());
    const double e_up = Luminance(e.cast<double>()) + impl->skybox.sun_horizontal_lux;
    impl->skybox_white = e_up / std::numbers::pi;
    const TextureLevel& level = impl->skybox.image->level(0);
    impl->pod.skybox = level.rgb_srgb.data();
    impl->pod.skybox_width = level.width;
    impl->pod.srgb_decode = SrgbDecodeTable();
    impl->pod.skybox_white = impl->skybox_white;
  }
  impl_ = std::move(impl);
}

double SkyModel::HorizontalIlluminancePerZenithLuminance(const Sky& sky) {
  Sky unit = sky;
  unit.type = Sky::Type::kDaylight;
  unit.zenith_luminance = 1.0f;
  Impl m;
  m.type = Sky::Type::kDaylight;
  m.pod.daylight = 1;
  m.SetUpDaylight(unit);
  const Eigen::Vector3d sun(m.pod.sun[0], m.pod.sun[1], m.pod.sun[2]);
  // luminance Y (the Perez function of Y scaled to the zenith) times cos(theta) over the upper
  // hemisphere, midpoint rule.
  constexpr int kRows = 256, kCols = 512;
  const double dphi = 2 * std::numbers::pi / kCols;
  double e = 0;
  for (int r = 0; r < kRows; ++r) {
    const double t0 = r * 0.5 * std::numbers::pi / kRows,
                 t1 = (r + 1) * 0.5 * std::numbers::pi / kRows;
    const double theta = 0.5 * (t0 + t1);
    // integral of cos(theta) d omega over the cell.
    const double w = dphi * 0.5 * (std::sin(t1) * std::sin(t1) - std::sin(t0) * std::sin(t0));
    double row = 0;
    for (int c = 0; c < kCols; ++c) {
      const Eigen::Vector3d d = DirectionFromAngles(theta, (c + 0.5) * dphi);
      const double cos_gamma = std::clamp(d.dot(sun), -1.0, 1.0);
      row += m.pod.y_scale *
             m.pod.perez_y(std::clamp(d.z(), 0.0, 1.0), std::acos(cos_gamma), cos_gamma);
    }
    e += row * w;
  }
  return e;
}

float SkyModel::PhysicalZenithLuminance(const Sky& sky) {
  const double per_zenith = HorizontalIlluminancePerZenithLuminance(sky);
  const Eigen::Vector3d sun = sky.sun_direction_W.normalized();
  const float elevation_deg =
      static_cast<float>(std::asin(std::clamp(sun.z(), -1.0, 1.0)) * 180.0 / std::numbers::pi);
  const double diffuse = SkyDiffuseHorizontalIlluminance(elevation_deg, sky.turbidity);
  return per_zenith > 0 ? static_cast<float>(diffuse / per_zenith) : 0.0f;
}

Eigen::Vector3f SkyModel::Radiance(const Eigen::Vector3f& dir_W) const {
  return impl_->Eval(dir_W.cast<double>()).cast<float>();
}

Eigen::Vector3f SkyModel::Background(const Eigen::Vector3f& dir_W) const {
  Eigen::Vector3f out;
  SkyBackground(impl_->pod, dir_W.x(), dir_W.y(), dir_W.z(), out.data());
  return out;
}

const SkyboxBackground& SkyModel::skybox() const { return impl_->skybox; }

float SkyModel::skybox_white_luminance() const { return static_cast<float>(impl_->skybox_white); }

Eigen::Vector3f SkyModel::Irradiance(const Eigen::Vector3f& n_W) const {
  Eigen::Vector3f out;
  SkyIrradiance(impl_->pod, n_W.x(), n_W.y(), n_W.z(), out.data());
  return out;
}

const SkyModelPod& SkyModel::pod() const { return impl_->pod; }

Eigen::Vector3f SkyModel::Sample(float u1, float u2, float* pdf) const {
  Eigen::Vector3f d;
  SkySampleDirection(impl_->sampling, u1, u2, pdf, d.data());
  return d;
}

float SkyModel::Pdf(const Eigen::Vector3f& dir_W) const {
  return SkyDirectionPdf(impl_->sampling, dir_W.x(), dir_W.y(), dir_W.z());
}

const SkySamplingPod& SkyModel::sampling_pod() const { return impl_->sampling; }

}  // namespace penumbra
