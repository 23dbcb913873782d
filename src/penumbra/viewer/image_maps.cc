#include "penumbra/viewer/image_maps.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "penumbra/core/error.h"

namespace penumbra {

std::array<uint8_t, 3> TurboColor(double x) {
  x = std::clamp(x, 0.0, 1.0);
  const double x2 = x * x, x3 = x2 * x, x4 = x2 * x2, x5 = x4 * x;
  const double r = 0.13572138 + 4.61539260 * x - 42.66032258 * x2 + 132.13108234 * x3 -
                   152.94239396 * x4 + 59.28637943 * x5;
  const double g = 0.09140261 + 2.19418839 * x + 4.84296658 * x2 - 14.18503333 * x3 +
                   4.27729857 * x4 + 2.82956604 * x5;
  const double b = 0.10667330 + 12.64194608 * x - 60.58204836 * x2 + 110.36276771 * x3 -
                   89.90310912 * x4 + 27.34824973 * x5;
  auto u8 = [](double v) {
    return static_cast<uint8_t>(std::lround(std::clamp(v, 0.0, 1.0) * 255.0));
  };
  return {u8(r), u8(g), u8(b)};
}

DepthColorMap ColorizeDepth(const ImageF& depth_m) {
  DepthColorMap out;
  out.image = ImageU8(depth_m.width, depth_m.height, 3, 0);
  // percentiles over a strided sample (at most ~64k pixels) of the valid depths
  std::vector<float> valid;
  const size_t n = depth_m.data.size();
  const size_t stride = std::max<size_t>(1, n / 65536);
  for (size_t i = 0; i < n; i += stride) {
    const float d = depth_m.data[i];
    if (d > 0 && std::isfinite(d)) valid.push_back(d);
  }
  if (valid.empty()) {
    out.near_m = 0;
    out.far_m = 1;
    return out;
  }
  auto pct = [&valid](double p) {
    const size_t k = std::min(valid.size() - 1, static_cast<size_t>(p * (valid.size() - 1)));
    std::nth_element(valid.begin(), valid.begin() + k, valid.end());
    return static_cast<double>(valid[k]);
  };
  out.near_m = pct(0.01);
  out.far_m = std::max(pct(0.99), out.near_m + 1e-3);
  // a lookup table over the range keeps the per-pixel cost to one multiply
  std::array<std::array<uint8_t, 3>, 256> lut;
  for (int i = 0; i < 256; ++i) lut[i] = TurboColor(i / 255.0);
  const double scale = 255.0 / (out.far_m - out.near_m);
  for (size_t i = 0; i < n; ++i) {
    const float d = depth_m.data[i];
    if (!(d > 0) || !std::isfinite(d)) continue;
    const int k = static_cast<int>(std::clamp((d - out.near_m) * scale + 0.5, 0.0, 255.0));
    std::copy(lut[k].begin(), lut[k].end(), out.image.data.begin() + 3 * i);
  }
  return out;
}

std::array<uint8_t, 3> SegmentColor(int32_t id) {
  // golden-ratio hue steps, full saturation, bright value
  const double h = std::fmod(0.1 + 0.618033988749895 * static_cast<double>(id), 1.0) * 6.0;
  const int sector = static_cast<int>(h);
  const double f = h - sector;
  const double v = 1.0, s = 0.75;
  const double p = v * (1 - s), q = v * (1 - s * f), t = v * (1 - s * (1 - f));
  double r = v, g = t, b = p;
  switch (sector % 6) {
    case 0:
      r = v, g = t, b = p;
      break;
    case 1:
      r = q, g = v, b = p;
      break;
    case 2:
      r = p, g = v, b = t;
      break;
    case 3:
      r = p, g = q, b = v;
      break;
    case 4:
      r = t, g = p, b = v;
      break;
    default:
      r = v, g = p, b = q;
      break;
  }
  auto u8 = [](double x) { return static_cast<uint8_t>(std::lround(x * 255.0)); };
  return {u8(r), u8(g), u8(b)};
}

ImageU8 SegmentationOverlay(const ImageU8& rgb, const ImageI32& ids) {
  if (rgb.channels != 3) throw Error("segmentation overlay: RGB image expected");
  if (rgb.width != ids.width || rgb.height != ids.height || ids.channels != 1)
    throw Error("segmentation overlay: the id image does not match the RGB image's size");
  ImageU8 out = rgb;
  const size_t n = ids.data.size();
  for (size_t i = 0; i < n; ++i) {
    const int32_t id = ids.data[i];
    if (id < 0) continue;
    const std::array<uint8_t, 3> c = SegmentColor(id);
    for (int k = 0; k < 3; ++k)
      out.data[3 * i + k] = static_cast<uint8_t>((out.data[3 * i + k] + c[k] + 1) / 2);
  }
  return out;
}

}  // namespace penumbra
