#include "penumbra/output/png_io.h"

#include <png.h>

#include <array>
#include <cerrno>
#include <chrono>
#include <csetjmp>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <memory>

#include "penumbra/core/error.h"
#include "penumbra/core/image_file_limits.h"
#include "penumbra/core/output_file.h"

// speed settings, measured on 640 x 480 frames of worlds/default.yaml (realtime tier),
// thread CPU time per image, zlib 1.2.13 / libpng 1.6.39:
//   rgb    level 1: none 6.7 ms 178 KB, sub 6.8-7.5 ms 149 KB, up 7.4 ms 179 KB,
//          paeth 8.9 ms 158 KB; level 3 sub 15.7 ms 134 KB; level 6 sub 36 ms 118 KB.
//   depth  level 1: none 1.5 ms 19 KB, sub 2.1 ms 21 KB, up 1.7 ms 13 KB, paeth 2.4 ms 11 KB.
//   seg    level 1: none 1.2 ms 8 KB, up 1.5 ms 6 KB.
// so the default is zlib level 1 (Z_BEST_SPEED) with one fixed filter per image kind
// ("sub" for colour, "up" for 16-bit depth/segmentation): about 10 ms of one core for
// the three images of a frame, 4-5x faster than level 6 at +25 % size. a fixed filter
// also spares libpng's per-row trial of all five filters.

namespace penumbra {
namespace {

constexpr size_t kErrLen = 256;

// libpng error hook: keep the message and unwind to the setjmp of the caller.
void OnPngError(png_structp png, png_const_charp msg) {
  char* err = static_cast<char*>(png_get_error_ptr(png));
  if (err != nullptr) {
    std::snprintf(err, kErrLen, "%s", msg != nullptr ? msg : "libpng error");
  }
  png_longjmp(png, 1);
}

void OnPngWarning(png_structp, png_const_charp) {}

void OnPngWrite(png_structp png, png_bytep data, png_size_t n) {
  auto* out = static_cast<std::vector<uint8_t>*>(png_get_io_ptr(png));
  out->insert(out->end(), data, data + n);
}

void OnPngFlush(png_structp) {}

int FilterFlag(const std::string& name, int auto_flag) {
  if (name == "auto") return auto_flag;
  if (name == "none") return PNG_FILTER_NONE;
  if (name == "sub") return PNG_FILTER_SUB;
  if (name == "up") return PNG_FILTER_UP;
  if (name == "avg") return PNG_FILTER_AVG;
  if (name == "paeth") return PNG_FILTER_PAETH;
  return -1;
}

// everything the setjmp-guarded encoder needs, as plain data so that a longjmp
// never skips a destructor.
struct EncodeJob {
  png_uint_32 width;
  png_uint_32 height;
  int color_type;
  int bit_depth;
  bool srgb_chunk;
  int level;
  int filter_flag;
  png_bytep* rows;
  std::vector<uint8_t>* out;
  char err[kErrLen];
};

bool RunEncode(EncodeJob* job) {
  png_structp png =
      png_create_write_struct(PNG_LIBPNG_VER_STRING, job->err, OnPngError, OnPngWarning);
  if (png == nullptr) {
    std::snprintf(job->err, kErrLen, "png_create_write_struct failed");
    return false;
  }
  png_infop info = png_create_info_struct(png);
  if (info == nullptr) {
    png_destroy_write_struct(&png, nullptr);
    std::snprintf(job->err, kErrLen, "png_create_info_struct failed");
    return false;
  }
  if (setjmp(png_jmpbuf(png))) {
    png_destroy_write_struct(&png, &info);
    return false;
  }
  png_set_write_fn(png, job->out, OnPngWrite, OnPngFlush);
  png_set_compression_level(png, job->level);
  png_set_filter(png, PNG_FILTER_TYPE_BASE, job->filter_flag);
  png_set_IHDR(png, info, job->width, job->height, job->bit_depth, job->color_type,
               PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_BASE, PNG_FILTER_TYPE_BASE);
  if (job->srgb_chunk) png_set_sRGB(png, info, PNG_sRGB_INTENT_PERCEPTUAL);
  png_write_info(png, info);
  png_write_image(png, job->rows);
  png_write_end(png, nullptr);
  png_destroy_write_struct(&png, &info);
  return true;
}

template <typename T>
void CheckImage(const Image<T>& image, int channels, const char* what) {
  if (image.width <= 0 || image.height <= 0) {
    throw Error(std::string(what) + ": empty image (" + std::to_string(image.width) + " x " +
                std::to_string(image.height) + ")");
  }
  if (image.channels != channels) {
    throw Error(std::string(what) + ": expected " + std::to_string(channels) + " channel(s), got " +
                std::to_string(image.channels));
  }
  const size_t expected = static_cast<size_t>(image.width) * image.height * image.channels;
  if (image.data.size() != expected) {
    throw Error(std::string(what) + ": data holds " + std::to_string(image.data.size()) +
                " samples, expected width x height x channels = " + std::to_string(expected));
  }
}

std::vector<uint8_t> Encode(png_uint_32 width, png_uint_32 height, int color_type, int bit_depth,
                            bool srgb_chunk, size_t raw_bytes, png_bytep* rows,
                            const PngEncodeOptions& options, int auto_filter) {
  options.ValidateOrThrow();
  std::vector<uint8_t> out;
  out.reserve(raw_bytes / 2 + 1024);
  EncodeJob job{width,
                height,
                color_type,
                bit_depth,
                srgb_chunk,
                options.compression_level,
                FilterFlag(options.filter, auto_filter),
                rows,
                &out,
                {}};
  if (!RunEncode(&job)) throw Error(std::string("PNG encoding failed: ") + job.err);
  return out;
}

// whole file under a temporary name, then renamed into place (core/output_file.h)
void WriteFileBytes(const std::string& path, const std::vector<uint8_t>& bytes) {
  WriteFileAtomic(path,
                  std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size()));
}

// plain-data state of the setjmp-guarded decoder.
struct DecodeJob {
  std::FILE* file;
  png_structp png;
  png_infop info;
  char err[kErrLen];
};

bool DecodeHeader(DecodeJob* job, png_uint_32* width, png_uint_32* height, int* channels,
                  int* bit_depth, size_t* row_bytes) {
  if (setjmp(png_jmpbuf(job->png))) return false;
  png_init_io(job->png, job->file);
  // libpng refuses larger IHDR sizes itself, before any row is allocated
  png_set_user_limits(job->png, kMaxImageFileSide, kMaxImageFileSide);
  png_read_info(job->png, job->info);
  png_set_expand(job->png);  // palette -> rgb, grey < 8 bits -> 8 bits, tRNS -> alpha
  png_set_interlace_handling(job->png);
  png_read_update_info(job->png, job->info);
  *width = png_get_image_width(job->png, job->info);
  *height = png_get_image_height(job->png, job->info);
  *channels = png_get_channels(job->png, job->info);
  *bit_depth = png_get_bit_depth(job->png, job->info);
  *row_bytes = png_get_rowbytes(job->png, job->info);
  return true;
}

bool DecodeRows(DecodeJob* job, png_bytep* rows) {
  if (setjmp(png_jmpbuf(job->png))) return false;
  png_read_image(job->png, rows);
  png_read_end(job->png, nullptr);
  return true;
}

}  // namespace

void PngEncodeOptions::ValidateOrThrow() const {
  if (compression_level < 0 || compression_level > 9) {
    throw ConfigError("", 0, "png.compression_level",
                      "got " + std::to_string(compression_level) + "; expected 0..9");
  }
  if (FilterFlag(filter, 0) < 0) {
    throw ConfigError("", 0, "png.filter",
                      "got '" + filter + "'; expected one of auto, none, sub, up, avg, paeth");
  }
}

std::vector<uint8_t> EncodePngRgb8(const ImageU8& image, const PngEncodeOptions& options) {
  CheckImage(image, 3, "EncodePngRgb8");
  std::vector<png_bytep> rows(image.height);
  for (int v = 0; v < image.height; ++v) {
    // libpng only reads rows while writing
    rows[v] = const_cast<png_bytep>(image.at(0, v));
  }
  return Encode(image.width, image.height, PNG_COLOR_TYPE_RGB, 8, true, image.data.size(),
                rows.data(), options, PNG_FILTER_SUB);
}

std::vector<uint8_t> EncodePngGray16(const ImageU16& image, const PngEncodeOptions& options) {
  CheckImage(image, 1, "EncodePngGray16");
  // PNG stores 16-bit samples big-endian (network byte order)
  std::vector<uint8_t> be(image.data.size() * 2);
  for (size_t i = 0; i < image.data.size(); ++i) {
    be[2 * i] = static_cast<uint8_t>(image.data[i] >> 8);
    be[2 * i + 1] = static_cast<uint8_t>(image.data[i] & 0xff);
  }
  std::vector<png_bytep> rows(image.height);
  for (int v = 0; v < image.height; ++v)
    rows[v] = be.data() + static_cast<size_t>(v) * image.width * 2;
  return Encode(image.width, image.height, PNG_COLOR_TYPE_GRAY, 16, false, be.size(), rows.data(),
                options, PNG_FILTER_UP);
}

namespace {
// adds the encoding (t0 to t1) and the write (t1 to now) to *times, if given.
void AddPngTimes(PngWriteTimes* times, std::chrono::steady_clock::time_point t0,
                 std::chrono::steady_clock::time_point t1) {
  if (!times) return;
  const auto t2 = std::chrono::steady_clock::now();
  times->encode_sec += std::chrono::duration<double>(t1 - t0).count();
  times->write_sec += std::chrono::duration<double>(t2 - t1).count();
}

// `encode()`'s PNG bytes written to `path`; the encode and write times added to `times`
template <typename Encode>
std::vector<uint8_t> EncodeAndWrite(const std::string& path, PngWriteTimes* times, Encode encode) {
  std::vector<uint8_t> bytes;
  const auto t0 = std::chrono::steady_clock::now();
  try {
    bytes = encode();
  } catch (const Error& e) {
    throw Error("cannot write PNG '" + path + "': " + e.what());
  }
  const auto t1 = std::chrono::steady_clock::now();
  WriteFileBytes(path, bytes);
  AddPngTimes(times, t0, t1);
  return bytes;
}
}  // namespace

std::vector<uint8_t> WritePngRgb8(const std::string& path, const ImageU8& image,
                                  const PngEncodeOptions& options, PngWriteTimes* times) {
  return EncodeAndWrite(path, times, [&] { return EncodePngRgb8(image, options); });
}

std::vector<uint8_t> WritePngGray16(const std::string& path, const ImageU16& image,
                                    const PngEncodeOptions& options, PngWriteTimes* times) {
  return EncodeAndWrite(path, times, [&] { return EncodePngGray16(image, options); });
}

PngImage ReadPng(const std::string& path) {
  std::FILE* f = std::fopen(path.c_str(), "rb");
  if (f == nullptr) throw Error("cannot read PNG '" + path + "': " + std::strerror(errno));
  std::unique_ptr<std::FILE, int (*)(std::FILE*)> file_guard(f, &std::fclose);

  std::array<uint8_t, 8> sig{};
  if (std::fread(sig.data(), 1, sig.size(), f) != sig.size() ||
      png_sig_cmp(sig.data(), 0, sig.size()) != 0) {
    throw Error("cannot read PNG '" + path + "': not a PNG file (bad signature)");
  }
  std::rewind(f);

  DecodeJob job{f, nullptr, nullptr, {}};
  job.png = png_create_read_struct(PNG_LIBPNG_VER_STRING, job.err, OnPngError, OnPngWarning);
  if (job.png == nullptr) throw Error("cannot read PNG '" + path + "': libpng init failed");
  job.info = png_create_info_struct(job.png);
  struct Destroy {
    DecodeJob* j;
    ~Destroy() { png_destroy_read_struct(&j->png, &j->info, nullptr); }
  } destroy{&job};
  if (job.info == nullptr) throw Error("cannot read PNG '" + path + "': libpng init failed");

  png_uint_32 width = 0, height = 0;
  int channels = 0, bit_depth = 0;
  size_t row_bytes = 0;
  if (!DecodeHeader(&job, &width, &height, &channels, &bit_depth, &row_bytes)) {
    throw Error("cannot read PNG '" + path + "': " + job.err);
  }
  // dimensions against the caps before the rows are allocated
  if (const std::string bad = ImageFileSizeProblem({width, height}, "PNG"); !bad.empty())
    throw Error("cannot read PNG '" + path + "': " + bad);
  if (bit_depth != 8 && bit_depth != 16) {
    throw Error("cannot read PNG '" + path + "': unsupported bit depth " +
                std::to_string(bit_depth));
  }
  std::vector<uint8_t> raw(row_bytes * height);
  std::vector<png_bytep> rows(height);
  for (png_uint_32 v = 0; v < height; ++v) rows[v] = raw.data() + v * row_bytes;
  if (!DecodeRows(&job, rows.data())) throw Error("cannot read PNG '" + path + "': " + job.err);

  PngImage img;
  img.width = static_cast<int>(width);
  img.height = static_cast<int>(height);
  img.channels = channels;
  img.bit_depth = bit_depth;
  const size_t n = static_cast<size_t>(width) * height * channels;
  img.samples.resize(n);
  for (png_uint_32 v = 0; v < height; ++v) {
    const uint8_t* row = rows[v];
    uint16_t* dst = img.samples.data() + static_cast<size_t>(v) * width * channels;
    const size_t row_samples = static_cast<size_t>(width) * channels;
    if (bit_depth == 8) {
      for (size_t i = 0; i < row_samples; ++i) dst[i] = row[i];
    } else {
      for (size_t i = 0; i < row_samples; ++i) {
        dst[i] = static_cast<uint16_t>((row[2 * i] << 8) | row[2 * i + 1]);
      }
    }
  }
  return img;
}

}  // namespace penumbra
