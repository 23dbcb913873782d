#pragma once
// texture images (PNG, JPEG) decoded to 8-bit RGB with libpng and libjpeg-turbo (TurboJPEG)
// directly, with the transformations OpenCV's imdecode(IMREAD_COLOR) applies (16-bit samples
// cut to their high byte, alpha dropped, palette and grey expanded to RGB; JPEG with the
// accurate integer DCT and smooth chroma upsampling), so the texels are the ones imdecode
// gives, without OpenCV's imgcodecs, whose GDAL, codec and ICU libraries (137 shared libraries)
// every program that loads a world would otherwise carry (the lean GPU pack, docs/gpu.md).
// not applied: a JPEG's EXIF orientation (imdecode turns the image; texture files carry none).

#include <cstdint>
#include <string>
#include <vector>

namespace penumbra {

/// an 8-bit RGB image, row-major, 3 bytes per pixel.
struct DecodedRgb8 {
  int width = 0;
  int height = 0;
  std::vector<uint8_t> rgb;
};

/// decodes a PNG (signature 89 50 4E 47) or JPEG (FF D8 FF) file's bytes.
/// @throws Error naming `what` when the bytes are neither, or the decoder fails (truncated or
///         corrupt data, an unsupported colour space such as CMYK JPEG).
DecodedRgb8 DecodeImageRgb8(const std::vector<unsigned char>& bytes, const std::string& what);

}  // namespace penumbra
