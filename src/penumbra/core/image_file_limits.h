#pragma once
// the size of an image file read from input that may come from others (a run folder, a dataset,
// a mesh's texture), checked from the file's own header before a decoder allocates its pixels:
// a 100-byte PNG may declare 1,000,000 x 1,000,000 pixels. docs/datasets.md ("Input limits")
// lists the caps.

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>

namespace penumbra {

/// most pixels (width x height) of an image read from a file: 2^27 = 134,217,728 (16384 x
/// 8192); its decoded samples then take at most 1 GiB at 4 channels of 16 bits.
inline constexpr uint64_t kMaxImageFilePixels = uint64_t{1} << 27;
/// most pixels of either side of such an image.
inline constexpr uint32_t kMaxImageFileSide = 1 << 15;

/// width and height as a PNG (IHDR) or JPEG (SOFn) header declares them.
struct ImageFileSize {
  uint32_t width = 0;
  uint32_t height = 0;
  /// PNG only (0 for JPEG): IHDR's bit depth (1..16) and colour type (0 grey, 2 RGB, 3 palette,
  /// 4 grey + alpha, 6 RGBA; PNG specification, section 11.2.2)
  int png_bit_depth = 0;
  int png_colour_type = 0;
};

/// the size that `bytes` (a whole file, or at least its beginning) declare: PNG by its signature
/// and IHDR chunk, JPEG by its SOI marker and first start-of-frame segment; nullopt for any other
/// format or when the header is cut off before the size.
std::optional<ImageFileSize> PeekImageFileSize(std::string_view bytes);

/// "" or the problem with a declared size: a side of 0 or above kMaxImageFileSide, or more than
/// kMaxImageFilePixels pixels ("PNG of 1000000 x 1000000 pixels; expected at most ...").
std::string ImageFileSizeProblem(const ImageFileSize& size, std::string_view format);

/// checks the size that an image's bytes declare (PeekImageFileSize) against the caps.
/// formats PeekImageFileSize does not know are left to the decoder.
/// @throws ConfigError(what, 0, "", problem) when the declared size is above a cap.
void CheckImageBytesSize(std::string_view bytes, const std::string& what);

/// the same for a file: reads its first 64 KiB (a JPEG's frame header may follow its EXIF data).
/// a missing file is left to the decoder (which names it); anything but a regular file (a
/// FIFO, which blocked open() for ever, a folder, a device) is refused (core/input_file.h).
/// @throws ConfigError(path, 0, "", problem) when the declared size is above a cap, or the
///         problem of OpenInputFile ("image file is not a regular file (a FIFO); ...").
void CheckImageFileSize(const std::filesystem::path& path);

}  // namespace penumbra
