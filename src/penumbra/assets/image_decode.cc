#include "penumbra/assets/image_decode.h"

#include <png.h>
#include <turbojpeg.h>

#include <csetjmp>
#include <cstring>

#include "penumbra/core/error.h"

namespace penumbra {
namespace {

// libpng reads from this cursor
struct PngSource {
  const unsigned char* data;
  size_t size;
  size_t pos;
};

void ReadPngBytes(png_structp png, png_bytep out, png_size_t n) {
  auto* s = static_cast<PngSource*>(png_get_io_ptr(png));
  if (n > s->size - s->pos) png_error(png, "unexpected end of data");
  std::memcpy(out, s->data + s->pos, n);
  s->pos += n;
}

// libpng's errors longjmp back to DecodePng; the message is kept
struct PngErrorText {
  char text[256] = "";
};
void OnDecodePngError(png_structp png, png_const_charp msg) {
  auto* e = static_cast<PngErrorText*>(png_get_error_ptr(png));
  std::strncpy(e->text, msg, sizeof(e->text) - 1);
  png_longjmp(png, 1);
}
void OnDecodePngWarning(png_structp, png_const_charp) {}

DecodedRgb8 DecodePng(const std::vector<unsigned char>& bytes, const std::string& what) {
  PngErrorText err;
  png_structp png =
      png_create_read_struct(PNG_LIBPNG_VER_STRING, &err, OnDecodePngError, OnDecodePngWarning);
  if (!png) throw Error(what + ": libpng could not start");
  png_infop info = png_create_info_struct(png);
  DecodedRgb8 out;
  std::vector<png_bytep> rows;
  PngSource src{bytes.data(), bytes.size(), 0};
  if (!info || setjmp(png_jmpbuf(png))) {
    png_destroy_read_struct(&png, info ? &info : nullptr, nullptr);
    throw Error(what + ": not a readable PNG (" + err.text + ")");
  }
  png_set_read_fn(png, &src, ReadPngBytes);
  png_read_info(png, info);
  const int color = png_get_color_type(png, info);
  const int depth = png_get_bit_depth(png, info);
  // as OpenCV 4.6's PngDecoder::readData for an 8-bit 3-channel result
  if (depth == 16) png_set_strip_16(png);
  png_set_strip_alpha(png);
  if (color == PNG_COLOR_TYPE_PALETTE) png_set_palette_to_rgb(png);
  if ((color & PNG_COLOR_MASK_COLOR) == 0 && depth < 8) png_set_expand_gray_1_2_4_to_8(png);
  if ((color & PNG_COLOR_MASK_COLOR) == 0) png_set_gray_to_rgb(png);
  png_set_interlace_handling(png);
  png_read_update_info(png, info);
  const png_uint_32 w = png_get_image_width(png, info), h = png_get_image_height(png, info);
  if (w < 1 || h < 1 || png_get_rowbytes(png, info) != static_cast<size_t>(w) * 3)
    png_error(png, "unexpected layout after the RGB transformations");
  out.width = static_cast<int>(w);
  out.height = static_cast<int>(h);
  out.rgb.resize(static_cast<size_t>(w) * h * 3);
  rows.resize(h);
  for (png_uint_32 y = 0; y < h; ++y) rows[y] = out.rgb.data() + static_cast<size_t>(y) * w * 3;
  png_read_image(png, rows.data());
  png_read_end(png, nullptr);
  png_destroy_read_struct(&png, &info, nullptr);
  return out;
}

DecodedRgb8 DecodeJpeg(const std::vector<unsigned char>& bytes, const std::string& what) {
  tjhandle tj = tjInitDecompress();
  if (!tj) throw Error(what + ": TurboJPEG could not start");
  struct Closer {
    tjhandle h;
    ~Closer() { tjDestroy(h); }
  } closer{tj};
  int w = 0, h = 0, subsamp = 0, colorspace = 0;
  auto* data = const_cast<unsigned char*>(bytes.data());
  const unsigned long size = static_cast<unsigned long>(bytes.size());
  if (tjDecompressHeader3(tj, data, size, &w, &h, &subsamp, &colorspace) != 0 || w < 1 || h < 1)
    throw Error(what + ": not a readable JPEG (" + tjGetErrorStr2(tj) + ")");
  DecodedRgb8 out;
  out.width = w;
  out.height = h;
  out.rgb.resize(static_cast<size_t>(w) * h * 3);
  // flags 0: the accurate integer DCT and smooth (fancy) upsampling, libjpeg's defaults
  if (tjDecompress2(tj, data, size, out.rgb.data(), w, 0, h, TJPF_RGB, 0) != 0)
    throw Error(what + ": not a readable JPEG (" + tjGetErrorStr2(tj) + ")");
  return out;
}

}  // namespace

DecodedRgb8 DecodeImageRgb8(const std::vector<unsigned char>& bytes, const std::string& what) {
  static const unsigned char kPng[4] = {0x89, 'P', 'N', 'G'};
  if (bytes.size() >= 8 && std::memcmp(bytes.data(), kPng, 4) == 0) return DecodePng(bytes, what);
  if (bytes.size() >= 3 && bytes[0] == 0xFF && bytes[1] == 0xD8 && bytes[2] == 0xFF)
    return DecodeJpeg(bytes, what);
  throw Error(what + ": not a readable image (" + std::to_string(bytes.size()) +
              " bytes); expected a PNG or JPEG file");
}

}  // namespace penumbra
