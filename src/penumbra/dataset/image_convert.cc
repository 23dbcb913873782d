#include "penumbra/dataset/image_convert.h"

#include <fstream>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "penumbra/core/error.h"
#include "penumbra/core/image_file_limits.h"
#include "penumbra/core/output_file.h"

namespace penumbra {
namespace {

namespace fs = std::filesystem;

cv::Mat ReadImage(const fs::path& path, int expected_type, const char* expected) {
  CheckImageFileSize(path);  // the declared size against the caps before decoding
  const cv::Mat m = cv::imread(path.string(), cv::IMREAD_UNCHANGED);
  if (m.empty())
    throw ConfigError(path.string(), 0, "",
                      "missing or not a readable PNG; expected " + std::string(expected));
  if (m.type() != expected_type)
    throw ConfigError(
        path.string(), 0, "",
        "image of OpenCV type " + cv::typeToString(m.type()) + "; expected " + expected);
  return m;
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

int64_t WriteTumDepthPng(const fs::path& mm_png, const fs::path& out) {
  const cv::Mat mm = ReadImage(mm_png, CV_16UC1, "a 16-bit greyscale depth PNG (millimetres)");
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

void WriteGreyPng(const fs::path& rgb_png, const fs::path& out) {
  // imread gives BGR channel order
  const cv::Mat bgr = ReadImage(rgb_png, CV_8UC3, "an 8-bit RGB PNG");
  cv::Mat grey;
  cv::cvtColor(bgr, grey, cv::COLOR_BGR2GRAY);
  WritePng(out, grey);
}

void CopyImage(const fs::path& from, const fs::path& to) {
  std::ifstream in(from, std::ios::binary);
  if (!in)
    throw ConfigError(from.string(), 0, "", "cannot open the image; expected it in the run folder");
  std::ostringstream bytes;
  bytes << in.rdbuf();
  WriteFileAtomic(to, bytes.str());
}

}  // namespace penumbra
