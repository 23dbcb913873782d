#pragma once
// the realtime tier's film development per pixel: the log-luminance sums of the auto exposure
// and the exposure, tone map and sRGB encoding of a pixel (render/film/film_math.h, as Film).

#include <cstdint>

#include "penumbra/core/host_device.h"
#include "penumbra/render/film/film_math.h"
#include "penumbra/render/transport/scene_view.h"

namespace penumbra::cuda {

/// the sum over row v of the log-luminance terms (film_math.h's LogLuminanceTerm), in column
/// order (the exposure's log-average; rows are summed on the host in row order).
PB_HOST_DEVICE inline double RowLogLuminance(const Float3* radiance, int width, int v,
                                             double min_luminance) {
  double sum = 0;
  for (int u = 0; u < width; ++u) {
    const Float3& c = radiance[static_cast<int64_t>(v) * width + u];
    const float rgb[3] = {c.x, c.y, c.z};
    sum += LogLuminanceTerm(rgb, min_luminance);
  }
  return sum;
}

/// the 8-bit sRGB code of every channel of one pixel (film_math.h's DevelopPixelIndices, then
/// the encoding table).
PB_HOST_DEVICE inline void DevelopPixel(const Float3& c, const float exposure[3], bool filmic,
                                        const uint8_t* lut, uint8_t out[3]) {
  const float rgb[3] = {c.x, c.y, c.z};
  int32_t index[3];
  DevelopPixelIndices(rgb, exposure, filmic, index);
  for (int k = 0; k < 3; ++k) out[k] = lut[index[k]];
}

}  // namespace penumbra::cuda
