#pragma once
// the exact ray-box test of the sun-occluder map (render/sky/sun_occluder_map.h)
// as a formula both backends can call (PB_HOST_DEVICE, core/host_device.h; the shared shading
// contract: Eigen-free).

#include "penumbra/core/host_device.h"

namespace penumbra {

/// slab test (Kay and Kajiya, "Ray tracing complex scenes", SIGGRAPH 1986) of the line
/// o + t d against the box |x_a| < half_a (box frame; o, d and half as 3 floats, d not
/// necessarily unit, d_len = |d|): true when the line passes through the box's interior with
/// a chord longer than min_chord (m) and, when entry_ahead, enters it at t > 0 (the origin
/// outside), else leaves it at t > 0 (the origin may be inside). false for a line parallel to
/// a slab outside it.
PB_HOST_DEVICE inline bool BoxChordAhead(const float o[3], const float d[3], const float half[3],
                                         float d_len, float min_chord, bool entry_ahead) {
  constexpr float kInf = __builtin_huge_valf();
  float t_near = entry_ahead ? 0.0f : -kInf, t_far = kInf;
  for (int a = 0; a < 3; ++a) {
    if (d[a] == 0) {
      if (!(o[a] < half[a] && o[a] > -half[a])) return false;
      continue;
    }
    const float inv = 1.0f / d[a];
    float t0 = (-half[a] - o[a]) * inv, t1 = (half[a] - o[a]) * inv;
    if (t0 > t1) {
      const float s = t0;
      t0 = t1, t1 = s;
    }
    t_near = t0 > t_near ? t0 : t_near;
    t_far = t1 < t_far ? t1 : t_far;
  }
  if (!(t_far < kInf)) return false;
  const bool ahead = entry_ahead ? t_near > 0 : t_far > 0;
  return ahead && (t_far - t_near) * d_len > min_chord;
}

}  // namespace penumbra
