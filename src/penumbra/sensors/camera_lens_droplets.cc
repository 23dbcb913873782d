#include "penumbra/sensors/camera_lens_droplets.h"

#include <algorithm>
#include <cmath>

#include "penumbra/core/rng.h"

namespace penumbra {

bool IsRaining(const EffectsFrame* effects) {
  if (!effects) return false;
  for (const ParticleSet& p : effects->particles)
    if (p.kind == ParticleKind::kRain && !p.position_W.empty()) return true;
  return false;
}

void ApplyLensDroplets(int count, double time_sec, uint64_t key, ImageU8* rgb) {
  if (count <= 0 || rgb->empty() || rgb->channels != 3) return;
  const int W = rgb->width, H = rgb->height;
  const ImageU8 src = *rgb;  // drops sample the undisturbed image
  const uint64_t epoch =
      static_cast<uint64_t>(std::max(0.0, std::floor(time_sec / kDropletLifetimeSec)));
  auto sample = [&](double x, double y, float* acc) {
    const int xi = std::clamp(static_cast<int>(std::lround(x)), 0, W - 1);
    const int yi = std::clamp(static_cast<int>(std::lround(y)), 0, H - 1);
    const uint8_t* p = src.at(xi, yi);
    for (int c = 0; c < 3; ++c) acc[c] += p[c];
  };
  for (int d = 0; d < count; ++d) {
    Rng rng(HashKeys(key, epoch, static_cast<uint64_t>(d)));
    const double cx = rng.UniformD() * W, cy = rng.UniformD() * H;
    const double r = (0.03 + 0.05 * rng.UniformD()) * std::min(W, H);
    const int u0 = std::max(0, static_cast<int>(cx - r)),
              u1 = std::min(W - 1, static_cast<int>(cx + r));
    const int v0 = std::max(0, static_cast<int>(cy - r)),
              v1 = std::min(H - 1, static_cast<int>(cy + r));
    for (int v = v0; v <= v1; ++v) {
      for (int u = u0; u <= u1; ++u) {
        const double dx = u - cx, dy = v - cy;
        const double dist = std::sqrt(dx * dx + dy * dy) / r;
        if (dist >= 1.0) continue;
        // inverted, minified, blurred view through the drop
        const double sx = cx - 0.6 * dx, sy = cy - 0.6 * dy;
        float acc[3] = {0, 0, 0};
        for (int j = -1; j <= 1; ++j)
          for (int i = -1; i <= 1; ++i) sample(sx + 0.2 * r * i, sy + 0.2 * r * j, acc);
        const double edge = std::clamp((1.0 - dist) / 0.2, 0.0, 1.0);
        const double w = edge * edge * (3.0 - 2.0 * edge);  // smoothstep
        const double shade = 1.0 - 0.1 * dist * dist;
        uint8_t* o = rgb->at(u, v);
        for (int c = 0; c < 3; ++c) {
          const double drop = acc[c] / 9.0 * shade;
          o[c] = static_cast<uint8_t>(std::clamp(std::lround((1 - w) * o[c] + w * drop), 0L, 255L));
        }
      }
    }
  }
}

}  // namespace penumbra
