#pragma once
// false-colour images the viewer streams beside RGB: depth as a colour map (with the range the
// page's scale bar shows) and segmentation as an overlay on the RGB image.

#include <array>
#include <cstdint>

#include "penumbra/core/image.h"

namespace penumbra {

/// the Turbo colour map (Mikhailov, "Turbo, An Improved Rainbow Colormap for Visualization",
/// Google AI blog 2019; polynomial fit by Ruofei Du): x in [0, 1] (clamped) -> sRGB uint8.
std::array<uint8_t, 3> TurboColor(double x);

/// a depth image drawn with TurboColor: near_m -> 0 (dark blue), far_m -> 1 (dark red).
struct DepthColorMap {
  ImageU8 image;      ///< (H x W x 3) sRGB; pixels without a hit (depth 0) are black
  double near_m = 0;  ///< depth of colour 0, m
  double far_m = 0;   ///< depth of colour 1, m
};

/// colours `depth_m` (H x W x 1, m, 0 = no hit). the range is the 1st..99th percentile of the
/// valid depths (robust to a few far hits); far_m > near_m always (a flat image gets a 1 mm
/// range). an image with no hit is all black with range 0..1.
DepthColorMap ColorizeDepth(const ImageF& depth_m);

/// a fixed colour per id (id >= 0), well spread in hue, the same in every frame and run.
std::array<uint8_t, 3> SegmentColor(int32_t id);

/// `rgb` with every pixel that has an id (>= 0 in `ids`, H x W x 1) blended half-and-half with
/// SegmentColor(id); background pixels keep their colour.
/// @throws Error if the sizes differ or rgb is not 3-channel.
ImageU8 SegmentationOverlay(const ImageU8& rgb, const ImageI32& ids);

}  // namespace penumbra
