#pragma once
// image conversions of dataset export: Penumbra's PNGs (output/camera_writer.h) to the pixel
// formats the datasets use. reading and encoding use OpenCV's imgcodecs; files are written whole
// under a temporary name and renamed into place (core/output_file.h).

#include <cstdint>
#include <filesystem>

namespace penumbra {

/// TUM RGB-D depth value (5000 per metre, 0 = no data) of a Penumbra depth value in
/// millimetres (0 = no return, 65535 = 65.535 m or more): 5 * mm, exact; 0 for 0, and 0 for
/// mm > 13107 (5 * mm would not fit 16 bits: TUM depth ends at 13.107 m).
uint16_t TumDepthFromMillimetres(uint16_t mm);

/// reads a 16-bit millimetre depth PNG and writes it as a 16-bit TUM depth PNG
/// (TumDepthFromMillimetres per pixel). returns the number of pixels that had a return
/// (mm > 0) but lie beyond 13.107 m and became 0.
/// @throws ConfigError naming `mm_png` if it is missing or not a 16-bit single-channel PNG;
///         Error naming `out` if it cannot be written.
int64_t WriteTumDepthPng(const std::filesystem::path& mm_png, const std::filesystem::path& out);

/// reads an 8-bit RGB PNG and writes its 8-bit greyscale version: OpenCV cvtColor
/// (round(0.299 R + 0.587 G + 0.114 B) in fixed point, ITU-R BT.601 luma on the stored sRGB
/// values).
/// @throws ConfigError naming `rgb_png` if it is missing or not an 8-bit colour PNG;
///         Error naming `out` if it cannot be written.
void WriteGreyPng(const std::filesystem::path& rgb_png, const std::filesystem::path& out);

/// copies a file byte for byte (written whole under a temporary name, then renamed).
/// @throws ConfigError naming `from` if it cannot be read; Error naming `to` if it cannot be
///         written.
void CopyImage(const std::filesystem::path& from, const std::filesystem::path& to);

}  // namespace penumbra
