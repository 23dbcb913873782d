#pragma once
// the image kinds a camera produces, in one table (the registry of image kinds).
//
// adding an image kind = its enumerator at the END of ImageKind and its row at the same place
// in kImageKinds; the world file's `outputs`, `--outputs`, run folders, camera writers, run
// descriptions and work estimates go through the table. the renderer's RenderedFrame
// (render/renderer.h) holds one image per kind, named in the row's comment.

#include <array>
#include <initializer_list>
#include <optional>
#include <string_view>

namespace penumbra {

/// one image a camera can produce; the value indexes kImageKinds and ImageKindSet.
enum class ImageKind : int {
  kRgb = 0,
  kDepth,
  kSegmentation,
  kRange,
  kNormals,
  kInstanceSegmentation,
  kSemanticSegmentation,
};
/// the number of image kinds.
inline constexpr int kImageKindCount = 7;

/// the element type of a kind's image as the renderer produces it (core/image.h).
enum class PixelType { kU8, kF32, kI32 };

/// how a kind's image is written to its file.
enum class ImageEncoding {
  kPngRgb8,               ///< 8-bit sRGB PNG as rendered
  kPngGray16Millimetres,  ///< metres as 16-bit millimetres, 0 = no hit, 65535 = 65.535 m or more
  kPngGray16IdPlusOne,    ///< int32 id + 1 as 16-bit, so -1 (background) is 0
  kPngGray16Id,           ///< int32 id as 16-bit, 0 = none
  kPngRgb8Normals,        ///< unit normals, each component (n + 1) / 2 as 8-bit, 0 = no hit
};

/// bytes per pixel of an image encoded as `e`, uncompressed (the work estimate's image size).
constexpr int EncodedBytesPerPixel(ImageEncoding e) {
  return e == ImageEncoding::kPngRgb8 || e == ImageEncoding::kPngRgb8Normals ? 3 : 2;
}

/// one row of the image-kind table.
struct ImageKindInfo {
  ImageKind kind;
  /// the name in the world file's `outputs` list, `--outputs` and run descriptions.
  std::string_view name;
  PixelType pixel;  ///< element type of the rendered image
  int channels;     ///< channels of the rendered image
  /// the folder of a camera's images of this kind in a run (<out>/<camera>/<folder>/NNNNNN.png).
  std::string_view folder;
  ImageEncoding encoding;
  /// intrinsics.json's "files" line of the kind; empty = not listed there.
  std::string_view file_note;
};

/// the image kinds, in ImageKind order (the order of folders, lists and files everywhere).
inline constexpr std::array<ImageKindInfo, kImageKindCount> kImageKinds = {{
    // RenderedFrame::rgb
    {ImageKind::kRgb, "rgb", PixelType::kU8, 3, "rgb", ImageEncoding::kPngRgb8,
     "rgb/NNNNNN.png: 8-bit sRGB"},
    // RenderedFrame::depth_m
    {ImageKind::kDepth, "depth", PixelType::kF32, 1, "depth", ImageEncoding::kPngGray16Millimetres,
     "depth/NNNNNN.png: 16-bit z-depth in millimetres, 0 = no return, 65535 = 65.535 m or more"},
    // RenderedFrame::geom_id
    {ImageKind::kSegmentation, "segmentation", PixelType::kI32, 1, "segmentation",
     ImageEncoding::kPngGray16IdPlusOne,
     "segmentation/NNNNNN.png: 16-bit MuJoCo geom id + 1, 0 = background"},
    // RenderedFrame::range_m
    {ImageKind::kRange, "range", PixelType::kF32, 1, "range", ImageEncoding::kPngGray16Millimetres,
     ""},
    // RenderedFrame::normal_O
    {ImageKind::kNormals, "normals", PixelType::kF32, 3, "normals", ImageEncoding::kPngRgb8Normals,
     ""},
    // RenderedFrame::body_id
    {ImageKind::kInstanceSegmentation, "instance_segmentation", PixelType::kI32, 1,
     "instance_segmentation", ImageEncoding::kPngGray16IdPlusOne, ""},
    // RenderedFrame::semantic_class
    {ImageKind::kSemanticSegmentation, "semantic_segmentation", PixelType::kI32, 1,
     "semantic_segmentation", ImageEncoding::kPngGray16Id, ""},
}};

// each row sits at its kind's index
constexpr bool ImageKindTableInOrder() {
  for (int i = 0; i < kImageKindCount; ++i)
    if (static_cast<int>(kImageKinds[i].kind) != i) return false;
  return true;
}
static_assert(ImageKindTableInOrder(), "kImageKinds must list the kinds in ImageKind order");

/// the table row of `kind`.
constexpr const ImageKindInfo& Info(ImageKind kind) { return kImageKinds[static_cast<int>(kind)]; }

/// the name of `kind` ("rgb", "depth", ...).
constexpr std::string_view ImageKindName(ImageKind kind) { return Info(kind).name; }

/// the kind named `name`, or nullopt for any other name.
constexpr std::optional<ImageKind> ImageKindFromName(std::string_view name) {
  for (const ImageKindInfo& k : kImageKinds)
    if (k.name == name) return k.kind;
  return std::nullopt;
}

/// true if `name` is an image kind's folder.
constexpr bool IsImageKindFolder(std::string_view name) {
  for (const ImageKindInfo& k : kImageKinds)
    if (k.folder == name) return true;
  return false;
}

/// a set of image kinds: one flag per kind, indexed by ImageKind.
class ImageKindSet {
 public:
  /// the empty set.
  constexpr ImageKindSet() = default;
  /// the set of `kinds`.
  constexpr ImageKindSet(std::initializer_list<ImageKind> kinds) {
    for (ImageKind k : kinds) on_[static_cast<int>(k)] = true;
  }

  /// the flag of `kind`.
  constexpr bool& operator[](ImageKind kind) { return on_[static_cast<int>(kind)]; }
  constexpr bool operator[](ImageKind kind) const { return on_[static_cast<int>(kind)]; }

  /// the number of kinds in the set.
  constexpr int count() const {
    int n = 0;
    for (bool b : on_) n += b ? 1 : 0;
    return n;
  }
  /// true when no kind is in the set.
  constexpr bool empty() const { return count() == 0; }

  /// the flag of the kind named `name`, or nullptr for any other name.
  bool* Flag(std::string_view name) {
    const std::optional<ImageKind> k = ImageKindFromName(name);
    return k ? &on_[static_cast<int>(*k)] : nullptr;
  }

  friend constexpr bool operator==(const ImageKindSet&, const ImageKindSet&) = default;

 private:
  std::array<bool, kImageKindCount> on_{};
};

}  // namespace penumbra
