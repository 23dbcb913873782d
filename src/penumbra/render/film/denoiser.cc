#include "penumbra/render/film/denoiser.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <string>
#include <vector>

#include "penumbra/core/error.h"

namespace penumbra {
namespace {

// B3-spline a-trous kernel (Dammertz et al. 2010, sec. 3).
constexpr float kKernel[5] = {1.0f / 16, 1.0f / 4, 3.0f / 8, 1.0f / 4, 1.0f / 16};
// demodulation guard: irradiance = radiance / max(albedo, kAlbedoEps).
constexpr float kAlbedoEps = 1e-3f;
// depth test tolerances (times sigma_depth): of the inverse depth, and of its planar change.
constexpr float kDepthRelativeTolerance = 0.01f;
constexpr float kDepthSlopeTolerance = 0.1f;

float DenoiseLuminance(const float* c) { return 0.2126f * c[0] + 0.7152f * c[1] + 0.0722f * c[2]; }

// x^e for e >= 0 by repeated squaring when e is a power of two (the default 128), else pow.
float PowCos(float x, float e, int squarings) {
  if (squarings < 0) return std::pow(x, e);
  for (int i = 0; i < squarings; ++i) x *= x;
  return x;
}

void CheckGuide(const ImageF* img, const char* name, int w, int h, int c) {
  if (!img) throw Error(std::string("Denoiser: guide '") + name + "' is missing");
  if (img->width != w || img->height != h || img->channels != c ||
      img->data.size() != static_cast<size_t>(w) * h * c)
    throw Error(std::string("Denoiser: guide '") + name + "' is " + std::to_string(img->width) +
                "x" + std::to_string(img->height) + "x" + std::to_string(img->channels) +
                "; expected " + std::to_string(w) + "x" + std::to_string(h) + "x" +
                std::to_string(c));
}

}  // namespace

void DenoiserSettings::ValidateOrThrow() const {
  if (iterations < 1 || iterations > 10)
    throw ConfigError("", 0, "denoiser.iterations",
                      "got " + std::to_string(iterations) + "; expected [1, 10]");
  if (!(sigma_luminance > 0) || !std::isfinite(sigma_luminance))
    throw ConfigError("", 0, "denoiser.sigma_luminance", "expected a finite value > 0");
  if (!(sigma_normal >= 0) || !std::isfinite(sigma_normal))
    throw ConfigError("", 0, "denoiser.sigma_normal", "expected a finite value >= 0");
  if (!(sigma_depth > 0) || !std::isfinite(sigma_depth))
    throw ConfigError("", 0, "denoiser.sigma_depth", "expected a finite value > 0");
}

Denoiser::Denoiser(const DenoiserSettings& settings) : settings_(settings) {
  settings_.ValidateOrThrow();
}

void Denoiser::Denoise(const ImageF& radiance, const DenoiserGuides& guides, ThreadPool* pool,
                       ImageF* out) const {
  const int w = radiance.width, h = radiance.height;
  if (radiance.channels != 3 || radiance.data.size() != static_cast<size_t>(w) * h * 3)
    throw Error("Denoiser: radiance must be an (H x W x 3) image");
  if (out == &radiance) throw Error("Denoiser: output must not alias the radiance image");
  CheckGuide(guides.albedo, "albedo", w, h, 3);
  CheckGuide(guides.normal, "normal", w, h, 3);
  CheckGuide(guides.depth, "depth", w, h, 1);
  if (guides.variance) CheckGuide(guides.variance, "variance", w, h, 1);
  *out = radiance;
  if (w == 0 || h == 0) return;

  const size_t n = static_cast<size_t>(w) * h;
  const float* albedo = guides.albedo->data.data();
  const float* normal = guides.normal->data.data();
  const float* depth = guides.depth->data.data();
  auto has_surface = [&](size_t i) { return depth[i] > 0 && std::isfinite(depth[i]); };
  // f(du, dv, j) for each pixel j at offset (du, dv), |du|, |dv| <= radius, from pixel (u, v)
  // that lies in the image and on a surface; rows outer, each left to right.
  auto for_surface_neighbours = [&](int u, int v, int radius, auto&& f) {
    for (int dv = -radius; dv <= radius; ++dv) {
      for (int du = -radius; du <= radius; ++du) {
        const int uu = u + du, vv = v + dv;
        if (uu < 0 || uu >= w || vv < 0 || vv >= h) continue;
        const size_t j = static_cast<size_t>(vv) * w + uu;
        if (has_surface(j)) f(du, dv, j);
      }
    }
  };

  // demodulated irradiance (3 channels) and the variance of its luminance.
  std::vector<float> cur(n * 3), next(n * 3), var(n), var_next(n);
  for (size_t i = 0; i < n; ++i) {
    for (int k = 0; k < 3; ++k)
      cur[i * 3 + k] = radiance.data[i * 3 + k] / std::max(albedo[i * 3 + k], kAlbedoEps);
  }
  // inverse depth 1/z is affine in screen coordinates on a plane, so a plane through pixel p
  // predicts it exactly at every neighbour. its screen-space gradient: the smaller one-sided
  // difference towards a surface neighbour (so that it does not straddle an edge).
  std::vector<float> inv_z(n, 0.0f), dwdx(n, 0.0f), dwdy(n, 0.0f);
  for (size_t i = 0; i < n; ++i)
    if (has_surface(i)) inv_z[i] = 1.0f / depth[i];
  ParallelForOrSerial(pool, h, [&](int64_t v) {
    for (int u = 0; u < w; ++u) {
      const size_t i = static_cast<size_t>(v) * w + u;
      if (!has_surface(i)) continue;
      auto grad = [&](int du, int dv) {
        float best = 0;
        bool found = false;
        for (int s : {-1, 1}) {
          const int uu = u + s * du, vv = static_cast<int>(v) + s * dv;
          if (uu < 0 || uu >= w || vv < 0 || vv >= h) continue;
          const size_t j = static_cast<size_t>(vv) * w + uu;
          if (!has_surface(j)) continue;
          const float d = (inv_z[j] - inv_z[i]) * s;
          if (!found || std::abs(d) < std::abs(best)) best = d;
          found = true;
        }
        return best;
      };
      dwdx[i] = grad(1, 0);
      dwdy[i] = grad(0, 1);
    }
  });

  const float sigma_n = settings_.sigma_normal;
  int squarings = -1;
  {
    float e = sigma_n;
    int s = 0;
    while (e > 1 && std::fmod(e, 2.0f) == 0) e *= 0.5f, ++s;
    if (e == 1) squarings = s;
    if (sigma_n == 0) squarings = -1;
  }
  // geometry weight of neighbour j seen from pixel i at offset (du, dv) pixels.
  auto geometry_weight = [&](size_t i, size_t j, int du, int dv, float* depth_term) {
    const float* ni = normal + i * 3;
    const float* nj = normal + j * 3;
    const float c = std::max(0.0f, ni[0] * nj[0] + ni[1] * nj[1] + ni[2] * nj[2]);
    const float wn = sigma_n == 0 ? 1.0f : PowCos(c, sigma_n, squarings);
    // deviation of the neighbour's inverse depth from the plane of pixel i, relative to a
    // tolerance of 1% of the depth plus 10% of the plane's change over the offset.
    const float slope_u = dwdx[i] * du, slope_v = dwdy[i] * dv;
    const float deviation = std::abs(inv_z[j] - (inv_z[i] + slope_u + slope_v));
    *depth_term = deviation / (settings_.sigma_depth *
                                   (kDepthSlopeTolerance * (std::abs(slope_u) + std::abs(slope_v)) +
                                    kDepthRelativeTolerance * inv_z[i]) +
                               1e-12f);
    return wn;
  };

  // initial variance: given, or the spatial variance over the 5x5 neighbourhood on the same
  // surface (geometry-weighted), which bounds the noise from above.
  if (guides.variance) {
    for (size_t i = 0; i < n; ++i) {
      const float a = std::max(DenoiseLuminance(albedo + i * 3), kAlbedoEps);
      var[i] = std::max(0.0f, guides.variance->data[i]) / (a * a);
    }
  } else {
    ParallelForOrSerial(pool, h, [&](int64_t v) {
      for (int u = 0; u < w; ++u) {
        const size_t i = static_cast<size_t>(v) * w + u;
        var[i] = 0;
        if (!has_surface(i)) continue;
        double sw = 0, s1 = 0, s2 = 0;
        for_surface_neighbours(u, static_cast<int>(v), 2, [&](int du, int dv, size_t j) {
          float dt = 0;
          const float wg = geometry_weight(i, j, du, dv, &dt) * std::exp(-dt);
          const double l = DenoiseLuminance(&cur[j * 3]);
          sw += wg;
          s1 += wg * l;
          s2 += wg * l * l;
        });
        const double mean = s1 / sw;
        var[i] = static_cast<float>(std::max(0.0, s2 / sw - mean * mean));
      }
    });
  }

  for (int it = 0; it < settings_.iterations; ++it) {
    const int step = 1 << it;
    ParallelForOrSerial(pool, h, [&](int64_t v) {
      for (int u = 0; u < w; ++u) {
        const size_t i = static_cast<size_t>(v) * w + u;
        if (!has_surface(i)) {
          for (int k = 0; k < 3; ++k) next[i * 3 + k] = cur[i * 3 + k];
          var_next[i] = var[i];
          continue;
        }
        // 3x3 gaussian of the variance for a stabler luminance test (SVGF, eq. 5).
        double gv = 0, gw = 0;
        for_surface_neighbours(u, static_cast<int>(v), 1, [&](int du, int dv, size_t j) {
          const double k = (du == 0 ? 0.5 : 0.25) * (dv == 0 ? 0.5 : 0.25);
          gv += k * var[j];
          gw += k;
        });
        const float li = DenoiseLuminance(&cur[i * 3]);
        const float lum_scale =
            settings_.sigma_luminance * static_cast<float>(std::sqrt(std::max(0.0, gv / gw))) +
            1e-6f * std::abs(li) + 1e-30f;
        float sw = 0, sr = 0, sg = 0, sb = 0, svar = 0;
        for (int kv = 0; kv < 5; ++kv) {
          const int dv = (kv - 2) * step;
          const int vv = static_cast<int>(v) + dv;
          if (vv < 0 || vv >= h) continue;
          for (int ku = 0; ku < 5; ++ku) {
            const int du = (ku - 2) * step;
            const int uu = u + du;
            if (uu < 0 || uu >= w) continue;
            const size_t j = static_cast<size_t>(vv) * w + uu;
            if (!has_surface(j)) continue;
            float depth_term = 0;
            const float wn = geometry_weight(i, j, du, dv, &depth_term);
            if (wn <= 0) continue;
            const float dr = cur[i * 3] - cur[j * 3], dg = cur[i * 3 + 1] - cur[j * 3 + 1],
                        db = cur[i * 3 + 2] - cur[j * 3 + 2];
            const float lum_term = std::sqrt((dr * dr + dg * dg + db * db) / 3) / lum_scale;
            const float wt = kKernel[ku] * kKernel[kv] * wn * std::exp(-(depth_term + lum_term));
            sw += wt;
            sr += wt * cur[j * 3];
            sg += wt * cur[j * 3 + 1];
            sb += wt * cur[j * 3 + 2];
            svar += wt * wt * var[j];
          }
        }
        // the centre tap has weight kKernel[2]^2 > 0, so sw > 0.
        next[i * 3] = sr / sw;
        next[i * 3 + 1] = sg / sw;
        next[i * 3 + 2] = sb / sw;
        var_next[i] = svar / (sw * sw);
      }
    });
    cur.swap(next);
    var.swap(var_next);
  }

  // remodulate surface pixels; others keep their radiance.
  for (size_t i = 0; i < n; ++i) {
    if (!has_surface(i)) continue;
    for (int k = 0; k < 3; ++k)
      out->data[i * 3 + k] = cur[i * 3 + k] * std::max(albedo[i * 3 + k], kAlbedoEps);
  }
}

}  // namespace penumbra
