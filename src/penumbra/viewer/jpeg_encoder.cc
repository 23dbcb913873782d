#include "penumbra/viewer/jpeg_encoder.h"

#include <fmt/format.h>
#include <turbojpeg.h>

#include <algorithm>

#include "penumbra/core/error.h"

namespace penumbra {

JpegEncoder::JpegEncoder() : handle_(tjInitCompress()) {
  if (!handle_) throw Error(std::string("TurboJPEG: ") + tjGetErrorStr2(nullptr));
}

JpegEncoder::~JpegEncoder() {
  if (handle_) tjDestroy(static_cast<tjhandle>(handle_));
}

std::string JpegEncoder::Encode(const ImageU8& image, int quality) {
  if (image.empty() || image.width <= 0 || image.height <= 0)
    throw Error("JPEG encoder: empty image");
  if (image.channels != 1 && image.channels != 3)
    throw Error(
        fmt::format("JPEG encoder: {} channels; expected 1 (grey) or 3 (RGB)", image.channels));
  if (image.data.size() != static_cast<size_t>(image.width) * image.height * image.channels)
    throw Error("JPEG encoder: image buffer does not match its size");
  quality = std::clamp(quality, 1, 100);
  unsigned char* out = nullptr;
  unsigned long size = 0;
  const int rc =
      tjCompress2(static_cast<tjhandle>(handle_), image.data.data(), image.width, 0, image.height,
                  image.channels == 3 ? TJPF_RGB : TJPF_GRAY, &out, &size,
                  image.channels == 3 ? TJSAMP_420 : TJSAMP_GRAY, quality, TJFLAG_FASTDCT);
  if (rc != 0) {
    const std::string why = tjGetErrorStr2(static_cast<tjhandle>(handle_));
    tjFree(out);
    throw Error("JPEG encoder: " + why);
  }
  std::string jpeg(reinterpret_cast<const char*>(out), size);
  tjFree(out);
  return jpeg;
}

ImageU8 DecodeJpeg(const std::string& jpeg) {
  tjhandle h = tjInitDecompress();
  if (!h) throw Error(std::string("TurboJPEG: ") + tjGetErrorStr2(nullptr));
  int w = 0, hgt = 0, subsamp = 0, colorspace = 0;
  const auto* src = reinterpret_cast<const unsigned char*>(jpeg.data());
  if (tjDecompressHeader3(h, src, jpeg.size(), &w, &hgt, &subsamp, &colorspace) != 0) {
    const std::string why = tjGetErrorStr2(h);
    tjDestroy(h);
    throw Error("JPEG decoder: " + why);
  }
  ImageU8 img(w, hgt, 3);
  if (tjDecompress2(h, src, jpeg.size(), img.data.data(), w, 0, hgt, TJPF_RGB,
                    TJFLAG_ACCURATEDCT) != 0) {
    const std::string why = tjGetErrorStr2(h);
    tjDestroy(h);
    throw Error("JPEG decoder: " + why);
  }
  tjDestroy(h);
  return img;
}

void AdaptiveJpegOptions::ValidateOrThrow() const {
  auto check_q = [](int q, const char* key) {
    if (q < 1 || q > 100)
      throw ConfigError("", 0, std::string("viewer.jpeg.") + key,
                        fmt::format("{}; expected 1..100", q));
  };
  check_q(min_quality, "min_quality");
  check_q(max_quality, "max_quality");
  check_q(initial_quality, "initial_quality");
  if (min_quality > max_quality)
    throw ConfigError("", 0, "viewer.jpeg.min_quality",
                      fmt::format("{} is above max_quality {}", min_quality, max_quality));
  if (initial_quality < min_quality || initial_quality > max_quality)
    throw ConfigError(
        "", 0, "viewer.jpeg.initial_quality",
        fmt::format("{}; expected {}..{}", initial_quality, min_quality, max_quality));
  if (!(target_bytes_per_sec > 0))
    throw ConfigError("", 0, "viewer.jpeg.target_bytes_per_sec", "expected a positive rate");
}

AdaptiveJpegQuality::AdaptiveJpegQuality(const AdaptiveJpegOptions& options)
    : options_(options), quality_(options.initial_quality) {
  options_.ValidateOrThrow();
}

void AdaptiveJpegQuality::Update(size_t frame_bytes, double interval_sec, int64_t frames_replaced) {
  int q = quality_;
  if (frames_replaced > 0) {
    q -= 10;
  } else if (interval_sec > 0) {
    const double budget = options_.target_bytes_per_sec * interval_sec;
    if (static_cast<double>(frame_bytes) > budget)
      q -= 5;
    else if (static_cast<double>(frame_bytes) < 0.6 * budget)
      q += 2;
  }
  quality_ = std::clamp(q, options_.min_quality, options_.max_quality);
}

}  // namespace penumbra
