#include "penumbra/sensors/depth_noise.h"

#include <Eigen/Core>
#include <algorithm>
#include <cmath>

#include "penumbra/core/error.h"
#include "penumbra/core/rng.h"
#include "penumbra/render/media_scene.h"
#include "penumbra/sensors/image_noise.h"

namespace penumbra {
namespace {

// theta^2 / (pi/2 - theta)^2, the angular growth term of Nguyen 2012 and Fankhauser 2015.
double AngleTerm(double theta) {
  const double d = std::max(1e-6, 0.5 * M_PI - theta);
  return theta * theta / (d * d);
}

}  // namespace

double DepthNoiseModel::AxialSigma(double z, double theta, double fx_px) const {
  switch (axial) {
    case Axial::kKinectV1:
      return 0.0012 + 0.0019 * (z - 0.4) * (z - 0.4) + 0.0001 / std::sqrt(z) * AngleTerm(theta);
    case Axial::kKinectV2:
      return 1e-3 * (1.5 - 0.5 * z + 0.3 * z * z + 0.1 * std::pow(z, 1.5) * AngleTerm(theta));
    case Axial::kStereoRms:
      return z * z * stereo_subpixel / (fx_px * stereo_baseline_m);
  }
  return 0;
}

double DepthNoiseModel::LateralSigmaPx(double theta) const {
  return lateral_sigma_px + lateral_theta_coeff * theta / std::max(1e-6, 0.5 * M_PI - theta);
}

DepthNoiseModel DepthNoisePreset(const DepthNoiseConfig& config, const std::string& key) {
  DepthNoiseModel m;
  m.name = config.preset;
  if (config.preset == "realsense_d435") {
    m.axial = DepthNoiseModel::Axial::kStereoRms;
    m.min_range_m = 0.2;
    m.max_range_m = 10.0;
    m.lateral_sigma_px = 0.5;
  } else if (config.preset == "kinect_v1") {
    m.axial = DepthNoiseModel::Axial::kKinectV1;
    m.min_range_m = 0.5;
    m.max_range_m = 4.0;
    m.lateral_sigma_px = 0.8;
    m.lateral_theta_coeff = 0.035;
  } else if (config.preset == "kinect_v2") {
    m.axial = DepthNoiseModel::Axial::kKinectV2;
    m.min_range_m = 0.5;
    m.max_range_m = 4.5;
    m.lateral_sigma_px = 1.6;
  } else {
    std::string names;
    for (std::string_view n : kDepthNoisePresets)
      names += (names.empty() ? "" : ", ") + std::string(n);
    throw ConfigError(
        "", 0, key + ".preset",
        "unknown depth noise preset '" + config.preset + "'; expected one of: " + names);
  }
  if (config.min_range_m) m.min_range_m = *config.min_range_m;
  if (config.max_range_m) m.max_range_m = *config.max_range_m;
  if (!(m.min_range_m >= 0) || !(m.max_range_m > m.min_range_m) || !std::isfinite(m.max_range_m))
    throw ConfigError("", 0, key + ".max_range_m",
                      "range [" + std::to_string(m.min_range_m) + ", " +
                          std::to_string(m.max_range_m) +
                          "] m; expected 0 <= min_range_m < max_range_m, finite");
  return m;
}

void ApplyDepthNoise(const ImageF& depth_z, const DepthNoiseInputs& in,
                     const DepthNoiseModel& model, uint64_t key, ImageF* out, ThreadPool* pool) {
  const int W = depth_z.width, H = depth_z.height;
  *out = ImageF(W, H, 1);
  const double cos_max = std::cos(model.max_incidence_deg * M_PI / 180.0);
  ParallelForOrSerial(pool, H, [&](int v) {
    for (int u = 0; u < W; ++u) {
      Rng rng(HashKeys(key, static_cast<uint64_t>(v) * static_cast<uint64_t>(W) + u));
      // incidence angle from the normal and the pixel ray (x, y, 1)
      double cos_theta = 1.0;
      if (in.normal_O && !in.normal_O->empty()) {
        const float* n = in.normal_O->at(u, v);
        const Eigen::Vector2d xy = in.camera
                                       ? in.camera->Unproject(u, v)
                                       : Eigen::Vector2d((u - in.cx) / in.fx, (v - in.cy) / in.fy);
        const Eigen::Vector3d ray(xy.x(), xy.y(), 1.0);
        cos_theta = std::abs(Eigen::Vector3d(n[0], n[1], n[2]).dot(ray)) / ray.norm();
      }
      const double theta = std::acos(std::clamp(cos_theta, 0.0, 1.0));
      // lateral: read the depth of a displaced pixel (edges jag; flat surfaces do not change)
      const double sl = model.LateralSigmaPx(theta);
      const int us =
          std::clamp(static_cast<int>(std::lround(u + sl * SampleStandardNormal(&rng))), 0, W - 1);
      const int vs =
          std::clamp(static_cast<int>(std::lround(v + sl * SampleStandardNormal(&rng))), 0, H - 1);
      const double z = *depth_z.at(us, vs);
      const double axial_n = SampleStandardNormal(&rng);
      const double drop_u = rng.UniformD();
      float& o = *out->at(u, v);
      o = 0.0f;
      if (!(z > 0) || z < model.min_range_m || z > model.max_range_m) continue;
      if (cos_theta < cos_max) continue;
      if (in.reflectance && !in.reflectance->empty()) {
        const float r = *in.reflectance->at(us, vs);
        if (r < model.min_reflectance) continue;  // dark, or < 0 = specular
      }
      if (in.transmittance && !in.transmittance->empty()) {
        const double t = *in.transmittance->at(us, vs);
        const double t2 = t * t;
        if (t2 < model.min_round_trip_transmittance || drop_u >= t2) continue;
      }
      o = static_cast<float>(z + model.AxialSigma(z, theta, in.fx) * axial_n);
    }
  });
}

double HomogeneousOpticalDepth(const HomogeneousMedium& medium, const Eigen::Vector3d& a_W,
                               const Eigen::Vector3d& b_W) {
  const double sigma = medium.sigma_t_per_m.cast<double>().mean();
  if (!(sigma > 0)) return 0.0;
  double t0 = 0.0, t1 = 1.0;  // segment parameters inside the region
  const Eigen::Vector3d d = b_W - a_W;
  if (medium.region) {
    for (int i = 0; i < 3; ++i) {
      const double lo = medium.region->min_W[i], hi = medium.region->max_W[i];
      if (std::abs(d[i]) < 1e-15) {
        if (a_W[i] < lo || a_W[i] > hi) return 0.0;
        continue;
      }
      double ta = (lo - a_W[i]) / d[i], tb = (hi - a_W[i]) / d[i];
      if (ta > tb) std::swap(ta, tb);
      t0 = std::max(t0, ta);
      t1 = std::min(t1, tb);
    }
    if (t1 <= t0) return 0.0;
  }
  const double len = d.norm() * (t1 - t0);
  if (medium.height_falloff_per_m <= 0) return sigma * len;
  constexpr int kSteps = 64;
  double sum = 0.0;
  for (int i = 0; i < kSteps; ++i) {
    const double t = t0 + (t1 - t0) * (i + 0.5) / kSteps;
    const double z = a_W.z() + t * d.z();
    sum += std::exp(-medium.height_falloff_per_m * std::max(0.0, z - medium.base_height_m));
  }
  return sigma * len * sum / kSteps;
}

ImageF DepthTransmittance(const ImageF& depth_z, const Camera& camera, const EffectsFrame& effects,
                          uint64_t key, ThreadPool* pool) {
  ImageF t(depth_z.width, depth_z.height, 1, 1.0f);
  if (effects.homogeneous_media.empty() && effects.grid_media.empty()) return t;
  MediaScene media;
  media.Build(&effects);
  if (media.empty()) return t;
  ParallelForOrSerial(pool, depth_z.height, [&](int v) {
    for (int u = 0; u < depth_z.width; ++u) {
      const double z = *depth_z.at(u, v);
      if (!(z > 0)) continue;
      const Ray r = camera.GenerateRay(static_cast<float>(u), static_cast<float>(v));
      const float len = r.d.norm();
      Rng rng(HashKeys(key, static_cast<uint64_t>(v) * static_cast<uint64_t>(depth_z.width) + u));
      const Eigen::Vector3f tr =
          media.Transmittance(r.o, r.d / len, 0.0f, static_cast<float>(z) * len, &rng);
      *t.at(u, v) = std::clamp(tr.mean(), 0.0f, 1.0f);
    }
  });
  return t;
}

}  // namespace penumbra
