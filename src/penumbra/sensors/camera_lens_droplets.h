#pragma once
// water drops on the lens while it rains. a simple documented model, not a physical simulation:
// each drop is a disc on the image (radius 3-8 % of the smaller image side); a drop on the front
// glass is far out of focus and acts as a small ball lens, so inside the disc the image shows a
// blurred, inverted, minified view of its surroundings: pixel p at distance d from the drop
// centre c shows the image, Gaussian-blurred with sigma = 2 % of the smaller image side, at
// c - 0.6 (p - c) (bilinear), blended in with a smooth edge over the outer 20 % of the radius and
// darkened by 10 % at the rim (total internal reflection at the drop's edge). drops are drawn for
// an epoch of kDropletLifetimeSec of sim time (they appear, stay and run off together), seeded by
// Rng(HashKeys(key, epoch, drop)).

#include <cstdint>
#include <optional>

#include "penumbra/core/image.h"
#include "penumbra/scene/effects_frame.h"

namespace penumbra {

/// sim time during which one set of drops stays on the lens, s.
inline constexpr double kDropletLifetimeSec = 2.0;

/// true if `effects` (may be null) holds rain particles.
bool IsRaining(const EffectsFrame* effects);

/// the number of drops on the lens at sim time `time_sec` when it was last under open sky in
/// the rain at `last_wet_time_sec` (nullopt = never): `count` then, falling linearly to 0 over
/// the kDropletLifetimeSec after it (round(count (1 - dt / kDropletLifetimeSec))).
int LensDropletCount(int count, const std::optional<double>& last_wet_time_sec, double time_sec);

/// draws `count` drops onto `rgb` ((H x W x 3) uint8) in place, for sim time `time_sec`;
/// `key` identifies the camera (e.g. HashKeys(seed, camera)).
void ApplyLensDroplets(int count, double time_sec, uint64_t key, ImageU8* rgb);

}  // namespace penumbra
