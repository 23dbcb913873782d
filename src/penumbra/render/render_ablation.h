#pragma once
// parts of the CPU renderer that `penumbra bench render --ablate` switches off, to measure what
// each costs (docs/performance.md, "What costs what"). not a world key and not part of
// RenderSettings: every run renders with all of them on (the defaults); a bench run with one
// off shows a different image (except sun-occluder, which only costs time).

namespace penumbra {

/// which parts render (true) or are switched off (false). CPU backend, realtime tier.
struct RenderAblation {
  bool mirror = true;          ///< the mirror layer (SurfaceMaterial::mirror); off: mirror 0
  bool mirror_sparse = true;   ///< weak mirrors at a quarter of the pixels (cpu/mirror_layer.h);
                               ///< off: a reflected ray at every pixel
  bool sky_volume = true;      ///< occluded sky light (SkyIrradianceVolume); off: unoccluded
  bool texture_filter = true;  ///< ray-cone texture filtering; off: bilinear in level 0
  bool shadows = true;         ///< shadow rays; off: every light sample counts as visible
  bool sun_occluder = true;    ///< skip sun rays static boxes block (sun_occluder_map.h)
  bool film = true;            ///< exposure and tone mapping; off: linear radiance only
};

}  // namespace penumbra
