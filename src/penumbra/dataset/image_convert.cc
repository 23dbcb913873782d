#include "penumbra/dataset/image_convert.h"

#include <fmt/format.h>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <optional>
#include <string>
#include <vector>

#include "penumbra/core/error.h"
#include "penumbra/core/image_file_limits.h"
#include "penumbra/core/output_file.h"
#include "penumbra/dataset/run_file.h"

namespace penumbra {
namespace {

namespace fs = std::filesystem;

// a run image's file and its decoded pixels (OpenCV: BGR order for colour)
struct CheckedPng {
  std::string bytes;
  cv::Mat image;
};

CheckedPng ReadCheckedPng(const RunCamera& cam, const std::string& kind, int64_t index) {
  const bool rgb = kind == "rgb";
  const int channels = rgb ? 3 : 1, bit_depth = rgb ? 8 : 16, colour_type = rgb ? 2 : 0;
  const std::string expected =
      fmt::format("{} PNG of {} x {} pixels (camera '{}' in camera_info.json)",
                  rgb ? "an 8-bit RGB" : "a 16-bit greyscale", cam.width, cam.height, cam.name);
  const fs::path relative = cam.RelativeImagePath(kind, index);
  const std::string file = (cam.run_dir / relative).string();
  // deflate never grows data by more than a few bytes per 16 KiB block; a PNG far larger than
  // its pixels is not one of Penumbra's
  const uint64_t raw = static_cast<uint64_t>(cam.width) * static_cast<uint64_t>(cam.height) *
                           static_cast<uint64_t>(channels * bit_depth / 8) +
                       static_cast<uint64_t>(cam.height);
  CheckedPng p;
  p.bytes = ReadRunFile(cam.run_dir, relative, 2 * raw + (1u << 20));
  // the header is checked (against the caps, then against camera_info.json) before anything is
  // allocated for the pixels
  const std::optional<ImageFileSize> declared = PeekImageFileSize(p.bytes);
  if (!declared || declared->png_bit_depth == 0)
    throw ConfigError(file, 0, "",
                      "not a PNG file (no PNG signature and header); expected " + expected);
  CheckImageBytesSize(p.bytes, file);
  const uint32_t w = declared->width, h = declared->height;
  const int depth = declared->png_bit_depth, type = declared->png_colour_type;
  if (w != static_cast<uint32_t>(cam.width) || h != static_cast<uint32_t>(cam.height))
    throw ConfigError(file, 0, "", fmt::format("{} x {} pixels; expected {}", w, h, expected));
  if (depth != bit_depth || type != colour_type)
    throw ConfigError(
        file, 0, "",
        fmt::format("PNG of bit depth {} and colour type {}; expected {}", depth, type, expected));
  const cv::Mat encoded(1, static_cast<int>(p.bytes.size()), CV_8UC1, p.bytes.data());
  try {
    p.image = cv::imdecode(encoded, cv::IMREAD_UNCHANGED);
  } catch (const cv::Exception&) {
    p.image.release();
  }
  if (p.image.empty())
    throw ConfigError(
        file, 0, "",
        "a truncated or corrupt PNG (it does not decode completely); expected " + expected);
  if (p.image.type() != (rgb ? CV_8UC3 : CV_16UC1) || p.image.cols != cam.width ||
      p.image.rows != cam.height)
    throw ConfigError(file, 0, "",
                      "decodes to an image of OpenCV type " + cv::typeToString(p.image.type()) +
                          "; expected " + expected);
  return p;
}

void WritePng(const fs::path& path, const cv::Mat& image) {
  std::vector<uint8_t> bytes;
  if (!cv::imencode(".png", image, bytes)) throw Error("cannot encode PNG " + path.string());
  WriteFileAtomic(path,
                  std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size()));
}

}  // namespace

uint16_t TumDepthFromMillimetres(uint16_t mm) {
  // 65535 / 5 = 13107: the largest millimetre value whose TUM value fits 16 bits
  return mm > 13107 ? 0 : static_cast<uint16_t>(5 * mm);
}

RunImage ReadRunImage(const RunCamera& cam, const std::string& kind, int64_t index) {
  const CheckedPng p = ReadCheckedPng(cam, kind, index);
  RunImage out;
  out.width = p.image.cols;
  out.height = p.image.rows;
  out.channels = p.image.channels();
  out.samples.resize(static_cast<size_t>(out.width) * out.height * out.channels);
  size_t i = 0;
  for (int y = 0; y < out.height; ++y) {
    if (out.channels == 3) {
      const cv::Vec3b* row = p.image.ptr<cv::Vec3b>(y);
      for (int x = 0; x < out.width; ++x)
        for (int c = 2; c >= 0; --c) out.samples[i++] = row[x][c];  // BGR -> RGB
    } else {
      const uint16_t* row = p.image.ptr<uint16_t>(y);
      for (int x = 0; x < out.width; ++x) out.samples[i++] = row[x];
    }
  }
  return out;
}

int64_t WriteTumDepthPng(const RunCamera& cam, int64_t index, const fs::path& out) {
  const cv::Mat mm = ReadCheckedPng(cam, "depth", index).image;
  cv::Mat tum(mm.rows, mm.cols, CV_16UC1);
  int64_t beyond = 0;
  for (int y = 0; y < mm.rows; ++y) {
    const uint16_t* in = mm.ptr<uint16_t>(y);
    uint16_t* o = tum.ptr<uint16_t>(y);
    for (int x = 0; x < mm.cols; ++x) {
      o[x] = TumDepthFromMillimetres(in[x]);
      beyond += in[x] > 13107;
    }
  }
  WritePng(out, tum);
  return beyond;
}

void WriteGreyPng(const RunCamera& cam, int64_t index, const fs::path& out, const fs::path* copy) {
  // imdecode gives BGR channel order
  const CheckedPng p = ReadCheckedPng(cam, "rgb", index);
  cv::Mat grey;
  cv::cvtColor(p.image, grey, cv::COLOR_BGR2GRAY);
  WritePng(out, grey);
  if (copy) WriteFileAtomic(*copy, p.bytes);
}

void CopyImage(const RunCamera& cam, const std::string& kind, int64_t index, const fs::path& to) {
  WriteFileAtomic(to, ReadCheckedPng(cam, kind, index).bytes);
}

}  // namespace penumbra
