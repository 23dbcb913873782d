#pragma once
// texture pixels as the renderer keeps them: 8-bit sRGB-encoded RGB (3 bytes per texel, as
// MuJoCo stores them), with a chain of mip levels, immutable and shared.
//
// storage: level 0 is the image as given; level l + 1 has max(1, floor(w_l / 2)) x
// max(1, floor(h_l / 2)) texels per face. each texel of level l + 1 is the area-weighted mean
// of the level-l texels its square covers (a box filter with fractional weights, so odd sizes
// keep the image's mean), taken in linear light: texels are decoded with the sRGB EOTF (IEC
// 61966-2-1), averaged in float, and re-encoded to the nearest 8-bit code. levels are built
// from the float values of the level above (not from its rounded bytes). faces (cube textures:
// six square faces stacked vertically) are filtered separately. the whole chain holds ~4/3 of
// the level-0 bytes: ~4 bytes per level-0 texel.
//
// sharing: a TextureImage is held by std::shared_ptr<const TextureImage>, so copies of a
// SceneDescription share the pixels instead of copying them, and TextureStore hands out one
// image for textures whose pixels are identical (equal content hash, then equal bytes).

#include <cstddef>
#include <cstdint>
#include <memory>
#include <unordered_map>
#include <vector>

namespace penumbra {

/// sRGB EOTF (IEC 61966-2-1): linear value of 8-bit code c, for every c in [0, 255].
const float* SrgbDecodeTable();

/// the 8-bit sRGB code nearest to the encoding of linear value `linear` (clamped to [0, 1]):
/// round(255 OETF(linear)), computed from thresholds between the decoded codes.
uint8_t EncodeSrgb8(float linear);

/// one mip level: (faces x height) rows of width texels, 3 bytes each, sRGB-encoded.
struct TextureLevel {
  int width = 0;                  ///< texels per row
  int height = 0;                 ///< rows per face
  std::vector<uint8_t> rgb_srgb;  ///< (faces x height x width x 3) bytes, face after face
};

/// an immutable 8-bit sRGB RGB image with its mip levels (file comment).
class TextureImage {
 public:
  /// builds the image and its mip chain from `rgb_srgb` ((height x width x 3) bytes, row-major;
  /// `faces` images of width x (height / faces) stacked vertically).
  /// @throws Error if width or height < 1, faces < 1, height is not a multiple of faces, or
  ///         rgb_srgb does not hold width x height x 3 bytes.
  TextureImage(int width, int height, int faces, std::vector<uint8_t> rgb_srgb);

  int width() const { return levels_[0].width; }
  /// total rows of level 0 (all faces).
  int height() const { return levels_[0].height * faces_; }
  int faces() const { return faces_; }
  int num_levels() const { return static_cast<int>(levels_.size()); }
  /// level l in [0, num_levels()); level 0 is the image as given.
  const TextureLevel& level(int l) const { return levels_[l]; }
  /// the level-0 bytes, (height x width x 3).
  const std::vector<uint8_t>& rgb_srgb() const { return levels_[0].rgb_srgb; }
  /// 64-bit hash of (width, height, faces, level-0 bytes); equal images have equal hashes.
  uint64_t content_hash() const { return hash_; }
  /// bytes of texel data held by all levels.
  size_t bytes() const;

  /// the content hash of an image given as its level-0 data, without building it.
  static uint64_t HashOf(int width, int height, int faces, const uint8_t* rgb_srgb, size_t size);

 private:
  int faces_ = 1;
  uint64_t hash_ = 0;
  std::vector<TextureLevel> levels_;
};

/// level-0 pixels to add to a TextureStore (not owned): `faces` images of width x
/// (height / faces) stacked vertically, rgb_srgb[0, size) with size = width x height x 3.
struct TextureSource {
  int width = 0;
  int height = 0;
  int faces = 1;
  const uint8_t* rgb_srgb = nullptr;
  size_t size = 0;
};

/// hands out one shared TextureImage per distinct image: textures with the same size, faces
/// and bytes get the same object. not thread-safe.
class TextureStore {
 public:
  /// the stored image equal to `source`, or a new one built from a copy of its bytes and stored.
  /// @throws Error as TextureImage's constructor.
  std::shared_ptr<const TextureImage> Add(const TextureSource& source);

  /// Add for every source, in order; the new images (and their mip levels) are built on up to
  /// `num_threads` threads (0 = the hardware's), each on its own, so the result does not depend
  /// on the thread count.
  /// @throws Error as TextureImage's constructor.
  std::vector<std::shared_ptr<const TextureImage>> AddAll(const std::vector<TextureSource>& sources,
                                                          int num_threads = 0);

  /// number of distinct images stored.
  int size() const { return static_cast<int>(by_hash_.size()); }

 private:
  std::unordered_multimap<uint64_t, std::shared_ptr<const TextureImage>> by_hash_;
};

/// what a set of textures costs in memory, counting every distinct image once.
struct TextureMemory {
  int textures = 0;   ///< textures with an image
  int images = 0;     ///< distinct TextureImage objects among them
  size_t texels = 0;  ///< level-0 texels of the distinct images
  size_t bytes = 0;   ///< texel bytes of the distinct images, all levels
  /// bytes per level-0 texel (0 when there are none).
  double bytes_per_texel() const { return texels > 0 ? static_cast<double>(bytes) / texels : 0; }
};

}  // namespace penumbra
