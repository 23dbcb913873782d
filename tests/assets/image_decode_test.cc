// assets/image_decode.h: PNG (8-bit RGB, RGBA, grey, palette with tRNS, 16-bit RGB, RGBA, grey,
// 1-bit grey, interlaced) and JPEG (4:2:0 colour, grey, baseline, progressive) decode to the same
// RGB bytes as OpenCV's imdecode(IMREAD_COLOR) + BGR2RGB, which textures were decoded with before;
// bad bytes are refused naming the file.

#include "penumbra/assets/image_decode.h"

#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

#include "penumbra/core/error.h"

namespace penumbra {
namespace {

// a deterministic test pattern of `type` (CV_8UC3, CV_8UC4, CV_8UC1, CV_16UC3, ...)
cv::Mat DecodePattern(int rows, int cols, int type) {
  cv::Mat m(rows, cols, type);
  const int ch = m.channels();
  for (int y = 0; y < rows; ++y)
    for (int x = 0; x < cols; ++x)
      for (int c = 0; c < ch; ++c) {
        const int v = (x * 37 + y * 91 + c * 53 + x * y * 7) & 0xFFFF;
        if (m.depth() == CV_16U)
          m.ptr<uint16_t>(y)[x * ch + c] = static_cast<uint16_t>(v * 13);
        else
          m.ptr<uint8_t>(y)[x * ch + c] = static_cast<uint8_t>(v);
      }
  return m;
}

// OpenCV's decode of `bytes`, RGB
std::vector<uint8_t> OpenCvRgb(const std::vector<unsigned char>& bytes, int* w, int* h) {
  const cv::Mat bgr = cv::imdecode(bytes, cv::IMREAD_COLOR);
  cv::Mat rgb;
  cv::cvtColor(bgr, rgb, cv::COLOR_BGR2RGB);
  *w = rgb.cols;
  *h = rgb.rows;
  std::vector<uint8_t> out;
  for (int y = 0; y < rgb.rows; ++y)
    out.insert(out.end(), rgb.ptr<uint8_t>(y), rgb.ptr<uint8_t>(y) + rgb.cols * 3);
  return out;
}

void ExpectSameAsOpenCv(const std::vector<unsigned char>& bytes, const std::string& label) {
  SCOPED_TRACE(label);
  int w = 0, h = 0;
  const std::vector<uint8_t> want = OpenCvRgb(bytes, &w, &h);
  const DecodedRgb8 got = DecodeImageRgb8(bytes, label);
  EXPECT_EQ(got.width, w);
  EXPECT_EQ(got.height, h);
  ASSERT_EQ(got.rgb.size(), want.size());
  EXPECT_TRUE(got.rgb == want);
}

TEST(ImageDecode, PngTexelsAreOpenCvs) {
  for (const int type : {CV_8UC3, CV_8UC4, CV_8UC1, CV_16UC3, CV_16UC4, CV_16UC1}) {
    std::vector<unsigned char> png;
    ASSERT_TRUE(cv::imencode(".png", DecodePattern(23, 37, type), png));
    ExpectSameAsOpenCv(png, "png type " + std::to_string(type));
  }
  // 1-bit grey (OpenCV writes bilevel PNGs with IMWRITE_PNG_BILEVEL)
  cv::Mat bits = DecodePattern(9, 17, CV_8UC1);
  cv::threshold(bits, bits, 127, 255, cv::THRESH_BINARY);
  std::vector<unsigned char> png;
  ASSERT_TRUE(cv::imencode(".png", bits, png, {cv::IMWRITE_PNG_BILEVEL, 1}));
  ExpectSameAsOpenCv(png, "png bilevel");
}

TEST(ImageDecode, PaletteAndInterlacedPngsAreOpenCvs) {
  // OpenCV writes neither: a 3x2 palette PNG with a tRNS chunk and a 5x4 Adam7-interlaced RGB
  // PNG, written with Python's zlib and struct (chunk CRCs included)
  const std::vector<unsigned char> palette = {
      0x89, 0x50, 0x4e, 0x47, 0x0d, 0x0a, 0x1a, 0x0a, 0x00, 0x00, 0x00, 0x0d, 0x49, 0x48,
      0x44, 0x52, 0x00, 0x00, 0x00, 0x03, 0x00, 0x00, 0x00, 0x02, 0x08, 0x03, 0x00, 0x00,
      0x00, 0xaa, 0xaa, 0x96, 0x28, 0x00, 0x00, 0x00, 0x0c, 0x50, 0x4c, 0x54, 0x45, 0xff,
      0x00, 0x00, 0x00, 0xff, 0x00, 0x00, 0x00, 0xff, 0x10, 0x20, 0x30, 0x54, 0xc5, 0xf1,
      0x9a, 0x00, 0x00, 0x00, 0x02, 0x74, 0x52, 0x4e, 0x53, 0x80, 0xff, 0x60, 0x12, 0xba,
      0xfe, 0x00, 0x00, 0x00, 0x10, 0x49, 0x44, 0x41, 0x54, 0x78, 0x9c, 0x63, 0x60, 0x60,
      0x64, 0x62, 0x60, 0x66, 0x62, 0x04, 0x00, 0x00, 0x26, 0x00, 0x0a, 0x1b, 0x1c, 0x09,
      0x79, 0x00, 0x00, 0x00, 0x00, 0x49, 0x45, 0x4e, 0x44, 0xae, 0x42, 0x60, 0x82};
  const std::vector<unsigned char> interlaced = {
      0x89, 0x50, 0x4e, 0x47, 0x0d, 0x0a, 0x1a, 0x0a, 0x00, 0x00, 0x00, 0x0d, 0x49, 0x48, 0x44,
      0x52, 0x00, 0x00, 0x00, 0x05, 0x00, 0x00, 0x00, 0x04, 0x08, 0x02, 0x00, 0x00, 0x01, 0xbe,
      0x56, 0x52, 0x81, 0x00, 0x00, 0x00, 0x4c, 0x49, 0x44, 0x41, 0x54, 0x78, 0x9c, 0x63, 0x60,
      0x00, 0x82, 0x13, 0x26, 0x0c, 0x0c, 0x29, 0x52, 0x0c, 0x0c, 0x1a, 0xb3, 0x18, 0x7a, 0xb6,
      0xd4, 0x7c, 0x38, 0xf7, 0x83, 0xc1, 0x88, 0x97, 0x61, 0x9a, 0x3a, 0x03, 0x43, 0xd4, 0x72,
      0xbb, 0x7d, 0x07, 0x77, 0x31, 0x88, 0xf8, 0x32, 0xb8, 0x45, 0xc9, 0x57, 0xa4, 0xdb, 0xad,
      0x2a, 0x89, 0xbd, 0xd3, 0x58, 0xc3, 0x60, 0xf3, 0x9c, 0x21, 0xef, 0x4b, 0xec, 0x02, 0xc6,
      0x5d, 0x97, 0xf8, 0xc4, 0x59, 0xa4, 0x4b, 0x00, 0xb2, 0xa4, 0x16, 0x7b, 0x7d, 0x85, 0x33,
      0xa4, 0x00, 0x00, 0x00, 0x00, 0x49, 0x45, 0x4e, 0x44, 0xae, 0x42, 0x60, 0x82};
  ExpectSameAsOpenCv(palette, "png palette");
  ExpectSameAsOpenCv(interlaced, "png interlaced");
  // the palette image's texels: red, green, blue / (16, 32, 48), blue, green (alpha dropped)
  const DecodedRgb8 p = DecodeImageRgb8(palette, "palette.png");
  EXPECT_EQ(p.rgb, (std::vector<uint8_t>{255, 0, 0, 0, 255, 0, 0, 0, 255, 16, 32, 48, 0, 0, 255, 0,
                                         255, 0}));
}

TEST(ImageDecode, JpegTexelsAreOpenCvs) {
  // colour (OpenCV 4.6 writes 4:2:0, so the chroma is upsampled) and grey, baseline and
  // progressive, two qualities
  for (const int type : {CV_8UC3, CV_8UC1})
    for (const int progressive : {0, 1})
      for (const int quality : {60, 95}) {
        std::vector<unsigned char> jpg;
        ASSERT_TRUE(cv::imencode(
            ".jpg", DecodePattern(31, 45, type), jpg,
            {cv::IMWRITE_JPEG_QUALITY, quality, cv::IMWRITE_JPEG_PROGRESSIVE, progressive}));
        ExpectSameAsOpenCv(jpg, "jpeg type " + std::to_string(type) + " progressive " +
                                    std::to_string(progressive) + " quality " +
                                    std::to_string(quality));
      }
}

TEST(ImageDecode, BadBytesAreRefusedNamingTheFile) {
  const auto error_of = [](const std::vector<unsigned char>& b) -> std::string {
    try {
      DecodeImageRgb8(b, "tex.png");
    } catch (const Error& e) {
      return e.what();
    }
    return "";
  };
  EXPECT_NE(error_of({}).find("tex.png: not a readable image (0 bytes); expected a PNG or JPEG"),
            std::string::npos);
  EXPECT_NE(error_of({'G', 'I', 'F', '8', '9', 'a', 0, 0, 0}).find("expected a PNG or JPEG"),
            std::string::npos);
  std::vector<unsigned char> png;
  ASSERT_TRUE(cv::imencode(".png", DecodePattern(8, 8, CV_8UC3), png));
  png.resize(png.size() / 2);
  EXPECT_NE(error_of(png).find("tex.png: not a readable PNG"), std::string::npos);
  std::vector<unsigned char> jpg;
  ASSERT_TRUE(cv::imencode(".jpg", DecodePattern(8, 8, CV_8UC3), jpg));
  jpg.resize(20);
  EXPECT_NE(error_of(jpg).find("tex.png: not a readable JPEG"), std::string::npos);
}

}  // namespace
}  // namespace penumbra
