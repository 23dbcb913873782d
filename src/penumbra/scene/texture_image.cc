#include "penumbra/scene/texture_image.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <string>
#include <thread>

#include "penumbra/core/error.h"
#include "penumbra/core/srgb.h"
#include "penumbra/core/thread_pool.h"

namespace penumbra {
namespace {

struct SrgbTables {
  std::array<float, 256> decode;
  // threshold[c]: the linear value halfway (in code space) between codes c and c + 1.
  std::array<float, 255> threshold;
  // start[k]: the code of linear value k / kStartSteps (a lower bound for [k, k + 1) / steps).
  static constexpr int kStartSteps = 4096;
  std::array<uint8_t, kStartSteps + 1> start;

  SrgbTables() {
    for (int c = 0; c < 256; ++c) decode[c] = static_cast<float>(SrgbToLinear(c / 255.0));
    for (int c = 0; c < 255; ++c)
      threshold[c] = static_cast<float>(SrgbToLinear((c + 0.5) / 255.0));
    int code = 0;
    for (int k = 0; k <= kStartSteps; ++k) {
      const float lin = static_cast<float>(k) / kStartSteps;
      while (code < 255 && lin >= threshold[code]) ++code;
      start[k] = static_cast<uint8_t>(code);
    }
  }
};

const SrgbTables& Tables() {
  static const SrgbTables tables;
  return tables;
}

// taps of a box filter that shrinks n texels to m <= n along one axis: output i averages the
// input interval [i n / m, (i + 1) n / m), input texel j weighted by its overlap.
struct Tap {
  int index;
  float weight;
};
std::vector<std::vector<Tap>> BoxTaps(int n, int m) {
  std::vector<std::vector<Tap>> taps(m);
  const double r = static_cast<double>(n) / m;
  for (int i = 0; i < m; ++i) {
    const double a = i * r, b = (i + 1) * r;
    for (int j = static_cast<int>(std::floor(a)); j < n && j < b; ++j) {
      const double overlap = std::min<double>(b, j + 1) - std::max<double>(a, j);
      if (overlap > 0) taps[i].push_back({j, static_cast<float>(overlap / r)});
    }
  }
  return taps;
}

// one face of a level as linear floats, (h x w x 3).
struct FloatFace {
  int w = 0, h = 0;
  std::vector<float> rgb;
};

// shrinks an image of w x h texels (row(y): pointer to row y, w x 3 linear floats) to w2 x h2:
// rows first, then columns. an exact halving takes the mean of each pair.
template <typename RowFn>
FloatFace Shrink(int w, int h, int w2, int h2, const RowFn& row) {
  const auto tx = BoxTaps(w, w2), ty = BoxTaps(h, h2);
  std::vector<float> rows(static_cast<size_t>(h) * w2 * 3);
  for (int y = 0; y < h; ++y) {
    const float* in = row(y);
    float* out = &rows[static_cast<size_t>(y) * w2 * 3];
    if (w == 2 * w2) {
      for (int k = 0; k < w2 * 3; k += 3)
        for (int c = 0; c < 3; ++c) out[k + c] = 0.5f * (in[2 * k + c] + in[2 * k + 3 + c]);
      continue;
    }
    for (int x = 0; x < w2; ++x) {
      float acc[3] = {0, 0, 0};
      for (const Tap& t : tx[x])
        for (int c = 0; c < 3; ++c) acc[c] += t.weight * in[3 * t.index + c];
      for (int c = 0; c < 3; ++c) out[3 * x + c] = acc[c];
    }
  }
  FloatFace f;
  f.w = w2;
  f.h = h2;
  f.rgb.assign(static_cast<size_t>(h2) * w2 * 3, 0.0f);
  for (int y = 0; y < h2; ++y) {
    float* out = &f.rgb[static_cast<size_t>(y) * w2 * 3];
    if (h == 2 * h2) {
      const float* a = &rows[static_cast<size_t>(2 * y) * w2 * 3];
      const float* b = a + static_cast<size_t>(w2) * 3;
      for (int k = 0; k < w2 * 3; ++k) out[k] = 0.5f * (a[k] + b[k]);
      continue;
    }
    for (const Tap& t : ty[y]) {
      const float* in = &rows[static_cast<size_t>(t.index) * w2 * 3];
      for (int k = 0; k < w2 * 3; ++k) out[k] += t.weight * in[k];
    }
  }
  return f;
}

}  // namespace

const float* SrgbDecodeTable() { return Tables().decode.data(); }

uint8_t EncodeSrgb8(float linear) {
  const SrgbTables& t = Tables();
  if (!(linear > 0)) return 0;
  if (linear >= 1) return 255;
  int code = t.start[static_cast<int>(linear * SrgbTables::kStartSteps)];
  while (code < 255 && linear >= t.threshold[code]) ++code;
  return static_cast<uint8_t>(code);
}

uint64_t TextureImage::HashOf(int width, int height, int faces, const uint8_t* rgb_srgb,
                              size_t size) {
  // a multiply-xorshift hash over 8-byte words (the bytes are compared as well before two
  // images are taken as equal, so this only has to spread well and be fast).
  constexpr uint64_t kMul = 0x9e3779b97f4a7c15ull;
  auto mix = [](uint64_t h, uint64_t v) {
    h ^= v;
    h *= kMul;
    return h ^ (h >> 29);
  };
  uint64_t h = mix(
      mix(mix(0x243f6a8885a308d3ull, static_cast<uint64_t>(width)), static_cast<uint64_t>(height)),
      static_cast<uint64_t>(faces));
  h = mix(h, size);
  size_t i = 0;
  for (; i + 8 <= size; i += 8) {
    uint64_t v;
    std::memcpy(&v, rgb_srgb + i, 8);
    h = mix(h, v);
  }
  uint64_t tail = 0;
  for (size_t k = 0; i + k < size; ++k) tail |= static_cast<uint64_t>(rgb_srgb[i + k]) << (8 * k);
  h = mix(h, tail);
  h ^= h >> 32;
  h *= 0xd6e8feb86659fd93ull;
  return h ^ (h >> 32);
}

TextureImage::TextureImage(int width, int height, int faces, std::vector<uint8_t> rgb_srgb)
    : faces_(faces) {
  if (width < 1 || height < 1 || faces < 1 || height % faces != 0)
    throw Error("texture image: expected width, height >= 1 and height a multiple of the " +
                std::to_string(faces) + " faces; got " + std::to_string(width) + " x " +
                std::to_string(height));
  const size_t expected = static_cast<size_t>(width) * height * 3;
  if (rgb_srgb.size() != expected)
    throw Error("texture image: expected width x height x 3 = " + std::to_string(expected) +
                " bytes; got " + std::to_string(rgb_srgb.size()));
  hash_ = HashOf(width, height, faces, rgb_srgb.data(), rgb_srgb.size());
  TextureLevel base;
  base.width = width;
  base.height = height / faces;
  base.rgb_srgb = std::move(rgb_srgb);
  levels_.push_back(std::move(base));

  const float* decode = SrgbDecodeTable();
  // per face: level 1 straight from the bytes, each further level from the floats above.
  std::vector<FloatFace> prev(faces);
  for (int l = 1;; ++l) {
    const TextureLevel& up = levels_[l - 1];
    if (up.width == 1 && up.height == 1) break;
    TextureLevel next;
    next.width = std::max(1, up.width / 2);
    next.height = std::max(1, up.height / 2);
    const size_t face_bytes = static_cast<size_t>(next.width) * next.height * 3;
    next.rgb_srgb.resize(face_bytes * faces);
    for (int f = 0; f < faces; ++f) {
      FloatFace cur;
      if (l == 1) {
        // level 0 is decoded one row at a time.
        const uint8_t* p = up.rgb_srgb.data() + static_cast<size_t>(f) * up.width * up.height * 3;
        std::vector<float> line(static_cast<size_t>(up.width) * 3);
        cur = Shrink(up.width, up.height, next.width, next.height, [&](int y) {
          const uint8_t* q = p + static_cast<size_t>(y) * up.width * 3;
          for (size_t k = 0; k < line.size(); ++k) line[k] = decode[q[k]];
          return line.data();
        });
      } else {
        const FloatFace& src = prev[f];
        cur = Shrink(src.w, src.h, next.width, next.height,
                     [&](int y) { return &src.rgb[static_cast<size_t>(y) * src.w * 3]; });
      }
      uint8_t* out = next.rgb_srgb.data() + f * face_bytes;
      for (size_t k = 0; k < face_bytes; ++k) out[k] = EncodeSrgb8(cur.rgb[k]);
      prev[f] = std::move(cur);
    }
    levels_.push_back(std::move(next));
  }
}

size_t TextureImage::bytes() const {
  size_t b = 0;
  for (const TextureLevel& l : levels_) b += l.rgb_srgb.size();
  return b;
}

std::shared_ptr<const TextureImage> TextureStore::Add(const TextureSource& source) {
  return AddAll({source}, 1).front();
}

std::vector<std::shared_ptr<const TextureImage>> TextureStore::AddAll(
    const std::vector<TextureSource>& sources, int num_threads) {
  const int n = static_cast<int>(sources.size());
  std::vector<std::shared_ptr<const TextureImage>> out(n);
  // the stored image equal to `src` (hash, then size and bytes), or null.
  auto find = [&](const TextureSource& src, uint64_t h) -> std::shared_ptr<const TextureImage> {
    const auto [first, last] = by_hash_.equal_range(h);
    for (auto it = first; it != last; ++it) {
      const TextureImage& im = *it->second;
      if (im.width() == src.width && im.height() == src.height && im.faces() == src.faces &&
          im.rgb_srgb().size() == src.size &&
          std::memcmp(im.rgb_srgb().data(), src.rgb_srgb, src.size) == 0)
        return it->second;
    }
    return nullptr;
  };
  auto same = [](const TextureSource& a, const TextureSource& b) {
    return a.width == b.width && a.height == b.height && a.faces == b.faces && a.size == b.size &&
           std::memcmp(a.rgb_srgb, b.rgb_srgb, a.size) == 0;
  };
  // serially: stored images, and for the others the first source with the same pixels.
  std::vector<uint64_t> hash(n);
  std::vector<int> first_of(n, -1);
  std::vector<int> build;  // sources whose image is new
  for (int i = 0; i < n; ++i) {
    const TextureSource& src = sources[i];
    hash[i] = TextureImage::HashOf(src.width, src.height, src.faces, src.rgb_srgb, src.size);
    if ((out[i] = find(src, hash[i]))) continue;
    for (int j : build)
      if (hash[j] == hash[i] && same(sources[j], src)) {
        first_of[i] = j;
        break;
      }
    if (first_of[i] < 0) {
      first_of[i] = i;
      build.push_back(i);
    }
  }
  auto make = [&](int64_t k) {
    const TextureSource& src = sources[build[k]];
    out[build[k]] = std::make_shared<const TextureImage>(
        src.width, src.height, src.faces,
        std::vector<uint8_t>(src.rgb_srgb, src.rgb_srgb + src.size));
  };
  if (num_threads == 1 || build.size() < 2) {
    for (size_t k = 0; k < build.size(); ++k) make(static_cast<int64_t>(k));
  } else {
    const int hw = static_cast<int>(std::thread::hardware_concurrency());
    ThreadPool pool(
        std::min(num_threads > 0 ? num_threads : std::max(hw, 1), static_cast<int>(build.size())));
    pool.ParallelFor(static_cast<int64_t>(build.size()), make);
  }
  for (int i : build) by_hash_.emplace(hash[i], out[i]);
  for (int i = 0; i < n; ++i)
    if (!out[i]) out[i] = out[first_of[i]];
  return out;
}

}  // namespace penumbra
