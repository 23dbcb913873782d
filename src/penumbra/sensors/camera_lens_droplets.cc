#include "penumbra/sensors/camera_lens_droplets.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>

#include "penumbra/core/rng.h"

namespace penumbra {

bool IsRaining(const EffectsFrame* effects) {
  if (!effects) return false;
  for (const ParticleSet& p : effects->particles)
    if (p.kind == ParticleKind::kRain && !p.position_W.empty()) return true;
  return false;
}

int LensDropletCount(int count, const std::optional<double>& last_wet_time_sec, double time_sec) {
  if (!last_wet_time_sec || count <= 0) return 0;
  const double dt = std::max(0.0, time_sec - *last_wet_time_sec);
  const double f = std::clamp(1.0 - dt / kDropletLifetimeSec, 0.0, 1.0);
  return static_cast<int>(std::lround(count * f));
}

void ApplyLensDroplets(int count, double time_sec, uint64_t key, ImageU8* rgb) {
  if (count <= 0 || rgb->empty() || rgb->channels != 3) return;
  const int W = rgb->width, H = rgb->height;
  // the defocused view through a drop: the image blurred once (Gaussian, sigma 2 % of the
  // smaller side), sampled bilinearly
  cv::Mat src(H, W, CV_8UC3, rgb->data.data());
  cv::Mat blurred;
  const double sigma = 0.02 * std::min(W, H);
  cv::GaussianBlur(src, blurred, cv::Size(0, 0), sigma, sigma, cv::BORDER_REFLECT);
  auto sample = [&](double x, double y, int c) {
    x = std::clamp(x, 0.0, W - 1.0);
    y = std::clamp(y, 0.0, H - 1.0);
    const int x0 = std::min(static_cast<int>(x), std::max(0, W - 2));
    const int y0 = std::min(static_cast<int>(y), std::max(0, H - 2));
    const int x1 = std::min(x0 + 1, W - 1), y1 = std::min(y0 + 1, H - 1);
    const double fx = x - x0, fy = y - y0;
    auto at = [&](int xx, int yy) { return static_cast<double>(blurred.at<cv::Vec3b>(yy, xx)[c]); };
    return (1 - fy) * ((1 - fx) * at(x0, y0) + fx * at(x1, y0)) +
           fy * ((1 - fx) * at(x0, y1) + fx * at(x1, y1));
  };
  const uint64_t epoch =
      static_cast<uint64_t>(std::max(0.0, std::floor(time_sec / kDropletLifetimeSec)));
  for (int d = 0; d < count; ++d) {
    Rng rng(HashKeys(key, epoch, static_cast<uint64_t>(d)));
    const double cx = rng.UniformD() * W, cy = rng.UniformD() * H;
    const double r = (0.03 + 0.05 * rng.UniformD()) * std::min(W, H);
    const int u0 = std::max(0, static_cast<int>(cx - r));
    const int u1 = std::min(W - 1, static_cast<int>(cx + r));
    const int v0 = std::max(0, static_cast<int>(cy - r));
    const int v1 = std::min(H - 1, static_cast<int>(cy + r));
    for (int v = v0; v <= v1; ++v) {
      for (int u = u0; u <= u1; ++u) {
        const double dx = u - cx, dy = v - cy;
        const double dist = std::sqrt(dx * dx + dy * dy) / r;
        if (dist >= 1.0) continue;
        // inverted, minified, defocused view through the drop
        const double sx = cx - 0.6 * dx, sy = cy - 0.6 * dy;
        const double edge = std::clamp((1.0 - dist) / 0.2, 0.0, 1.0);
        const double w = edge * edge * (3.0 - 2.0 * edge);  // smoothstep
        const double shade = 1.0 - 0.1 * dist * dist;
        uint8_t* o = rgb->at(u, v);
        for (int c = 0; c < 3; ++c) {
          const double drop = sample(sx, sy, c) * shade;
          o[c] = static_cast<uint8_t>(std::clamp(std::lround((1 - w) * o[c] + w * drop), 0L, 255L));
        }
      }
    }
  }
}

}  // namespace penumbra
