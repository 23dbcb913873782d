#pragma once
// image conversions of dataset export: Penumbra's PNGs (output/camera_writer.h) to the pixel
// formats the datasets use. every image is read from the run folder with ReadRunFile
// (dataset/run_file.h: no symbolic link followed) and checked before it is used: its PNG header
// must give the camera's width and height from camera_info.json and the format Penumbra writes
// for the kind (rgb: 8-bit RGB, colour type 2; depth: 16-bit greyscale, colour type 0), the file
// must be at most 2 x its raw pixel size + 1 MiB, and it must decode completely (OpenCV's
// imgcodecs), so a truncated or corrupt PNG is refused, never copied. outputs are written whole
// under a temporary name and renamed into place (core/output_file.h).

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "penumbra/dataset/run_folder.h"

namespace penumbra {

/// TUM RGB-D depth value (5000 per metre, 0 = no data) of a Penumbra depth value in
/// millimetres (0 = no return, 65535 = 65.535 m or more): 5 * mm, exact; 0 for 0, and 0 for
/// mm > 13107 (5 * mm would not fit 16 bits: TUM depth ends at 13.107 m).
uint16_t TumDepthFromMillimetres(uint16_t mm);

/// a checked image of a run's camera, its samples as stored.
struct RunImage {
  int width = 0, height = 0;
  int channels = 0;  ///< 3 for rgb (R, G, B), 1 for depth (millimetres)
  /// (height x width x channels) samples, row-major, channels interleaved.
  std::vector<uint16_t> samples;
};

/// reads and checks (see above) the image `kind` ("rgb" or "depth") of frame `index` of `cam`.
/// @throws ConfigError naming the file: missing, a symbolic link, not a regular file, too
///         large, not a PNG, another size or format than the run's metadata says, truncated or
///         corrupt.
RunImage ReadRunImage(const RunCamera& cam, const std::string& kind, int64_t index);

/// reads frame `index`'s depth image of `cam` (checked as ReadRunImage) and writes it as a 16-bit
/// TUM depth PNG (TumDepthFromMillimetres per pixel). returns the number of pixels that had a
/// return (mm > 0) but lie beyond 13.107 m and became 0.
/// @throws ConfigError as ReadRunImage; Error naming `out` if it cannot be written.
int64_t WriteTumDepthPng(const RunCamera& cam, int64_t index, const std::filesystem::path& out);

/// reads frame `index`'s rgb image of `cam` (checked as ReadRunImage) and writes its 8-bit
/// greyscale version: OpenCV cvtColor (round(0.299 R + 0.587 G + 0.114 B) in fixed point,
/// ITU-R BT.601 luma on the stored sRGB values); with `copy` also the checked file itself there,
/// byte for byte.
/// @throws ConfigError as ReadRunImage; Error naming `out` if it cannot be written.
void WriteGreyPng(const RunCamera& cam, int64_t index, const std::filesystem::path& out,
                  const std::filesystem::path* copy = nullptr);

/// copies the image `kind` of frame `index` of `cam` to `to` byte for byte, once it has been
/// checked as ReadRunImage does (written whole under a temporary name, then renamed).
/// @throws ConfigError as ReadRunImage; Error naming `to` if it cannot be written.
void CopyImage(const RunCamera& cam, const std::string& kind, int64_t index,
               const std::filesystem::path& to);

}  // namespace penumbra
