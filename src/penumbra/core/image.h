#pragma once
// a dense, row-major, interleaved image buffer.

#include <cstddef>
#include <cstdint>
#include <vector>

namespace penumbra {

/// (height x width x channels) image of T, row-major, channels interleaved;
/// pixel (u, v) = column u, row v, row 0 at the top.
template <typename T>
struct Image {
  int width = 0;
  int height = 0;
  int channels = 1;
  std::vector<T> data;

  Image() = default;
  Image(int w, int h, int c, T fill = T{})
      : width(w), height(h), channels(c), data(static_cast<size_t>(w) * h * c, fill) {}

  /// pointer to the first channel of pixel (u, v); no bounds check.
  T* at(int u, int v) { return data.data() + (static_cast<size_t>(v) * width + u) * channels; }
  const T* at(int u, int v) const {
    return data.data() + (static_cast<size_t>(v) * width + u) * channels;
  }
  bool empty() const { return data.empty(); }
};

using ImageU8 = Image<uint8_t>;
using ImageU16 = Image<uint16_t>;
using ImageF = Image<float>;
using ImageI32 = Image<int32_t>;

}  // namespace penumbra
