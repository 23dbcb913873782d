#pragma once
// PNG files for camera outputs (libpng 1.6). encoding favours speed over size
// (zlib level 1, one fixed row filter) because frames are written at video rates,
// and the bytes are a pure function of the image: no time, text or other
// metadata chunks are written.
//
// format: W3C "Portable Network Graphics (PNG) Specification (Third Edition)".

#include <cstdint>
#include <string>
#include <vector>

#include "penumbra/core/image.h"

namespace penumbra {

/// PNG encoder speed/size settings. defaults are tuned for rendered frames (see
/// png_io.cc for the measurements behind them).
struct PngEncodeOptions {
  /// zlib level 0..9 (0 = store, 1 = Z_BEST_SPEED, 9 = smallest).
  int compression_level = 1;
  /// row filter used for every row: "none", "sub", "up", "avg", "paeth", or "auto" =
  /// "sub" for 8-bit RGB and "up" for 16-bit greyscale.
  std::string filter = "auto";

  /// @throws ConfigError for a level outside [0, 9] or an unknown filter name.
  void ValidateOrThrow() const;
};

/// encodes an (H x W x 3) uint8 sRGB image as an 8-bit RGB PNG with an sRGB chunk.
/// @throws Error if the image is empty, has channels != 3 or a data size that does not
///         match width x height x channels, or if libpng fails.
std::vector<uint8_t> EncodePngRgb8(const ImageU8& image, const PngEncodeOptions& options = {});

/// encodes an (H x W x 1) uint16 image as a 16-bit greyscale PNG (values stored exactly).
/// @throws Error as EncodePngRgb8 (channels must be 1).
std::vector<uint8_t> EncodePngGray16(const ImageU16& image, const PngEncodeOptions& options = {});

/// where WritePngRgb8 / WritePngGray16 spent their time, s (added to by each call given one).
struct PngWriteTimes {
  double encode_sec = 0;  ///< the PNG encoding (libpng, zlib)
  double write_sec = 0;   ///< writing the bytes to the file and renaming it into place
};

/// writes EncodePngRgb8(image) to `path` (replacing an existing file): whole under a
/// temporary name, then renamed into place (core/output_file.h), so `path` is never a
/// truncated PNG. returns the bytes written. `times` (if given): the encoding's and the
/// write's wall time are added to it.
/// @throws Error naming `path` and the reason (bad image, cannot open, short write).
std::vector<uint8_t> WritePngRgb8(const std::string& path, const ImageU8& image,
                                  const PngEncodeOptions& options = {},
                                  PngWriteTimes* times = nullptr);

/// writes EncodePngGray16(image) to `path` as WritePngRgb8 does; returns the bytes written.
/// @throws Error naming `path` and the reason.
std::vector<uint8_t> WritePngGray16(const std::string& path, const ImageU16& image,
                                    const PngEncodeOptions& options = {},
                                    PngWriteTimes* times = nullptr);

/// a decoded PNG: samples as stored in the file (palette images are expanded to
/// RGB, greyscale below 8 bits to 8 bits; 16-bit samples are kept exact).
struct PngImage {
  int width = 0;
  int height = 0;
  int channels = 0;   ///< 1 grey, 2 grey + alpha, 3 RGB, 4 RGBA
  int bit_depth = 0;  ///< 8 or 16
  /// (height x width x channels) samples, row-major, channels interleaved, in
  /// [0, 255] or [0, 65535] depending on bit_depth.
  std::vector<uint16_t> samples;
};

/// reads a PNG file (used by tests and tools).
/// @throws Error naming `path` and the reason (missing file, not a PNG, corrupt data).
PngImage ReadPng(const std::string& path);

}  // namespace penumbra
