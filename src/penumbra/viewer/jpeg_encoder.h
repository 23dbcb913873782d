#pragma once
// JPEG compression of camera images for the live viewer (libjpeg-turbo's TurboJPEG API), and
// the quality control that keeps the stream within a byte budget and the clients' pace.

#include <cstdint>
#include <string>

#include "penumbra/core/image.h"

namespace penumbra {

/// one TurboJPEG compressor (reused across frames; one thread at a time).
class JpegEncoder {
 public:
  /// @throws Error if TurboJPEG cannot be initialised.
  JpegEncoder();
  ~JpegEncoder();
  JpegEncoder(const JpegEncoder&) = delete;
  JpegEncoder& operator=(const JpegEncoder&) = delete;

  /// the JPEG file of `image` (H x W x 3 sRGB or H x W x 1 grey, uint8) at `quality` (1..100,
  /// clamped; 4:2:0 chroma subsampling for colour).
  /// @throws Error for an empty image, a channel count other than 1 or 3, or a libjpeg failure.
  std::string Encode(const ImageU8& image, int quality);

 private:
  void* handle_ = nullptr;
};

/// decodes a JPEG file to H x W x 3 sRGB (tests, benchmarks).
/// @throws Error naming the libjpeg problem for data that is not a JPEG file.
ImageU8 DecodeJpeg(const std::string& jpeg);

/// the limits of the adaptive quality.
struct AdaptiveJpegOptions {
  int min_quality = 30;
  int max_quality = 90;
  int initial_quality = 80;
  /// bytes per second one stream may use; frames above their share lower the quality.
  double target_bytes_per_sec = 6e6;
  /// @throws ConfigError (key "viewer.jpeg.<field>") for qualities outside 1..100, min > max,
  ///         initial outside [min, max] or a non-positive byte budget.
  void ValidateOrThrow() const;
};

/// quality of one stream, adjusted after every frame: down by 10 when a client could not keep up
/// (frames replaced before sending), down by 5 when the frame used more than its share of the
/// byte budget, up by 2 when it used less than 60 % of it and no frame was dropped.
class AdaptiveJpegQuality {
 public:
  explicit AdaptiveJpegQuality(const AdaptiveJpegOptions& options = {});
  /// the quality for the next frame.
  int quality() const { return quality_; }
  /// the last frame took `frame_bytes` and came `interval_sec` after the previous one (0 =
  /// unknown: the budget is not checked); `frames_replaced` frames of this stream were replaced
  /// unsent since the last update.
  void Update(size_t frame_bytes, double interval_sec, int64_t frames_replaced);

 private:
  AdaptiveJpegOptions options_;
  int quality_;
};

}  // namespace penumbra
