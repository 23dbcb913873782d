#include "penumbra/output/png_io.h"

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "common/temp_dir.h"
#include "penumbra/core/error.h"
#include "penumbra/core/rng.h"

namespace penumbra {
namespace {

using testing::ReadBytes;
using testing::TempDir;

// an rgb image with smooth gradients, hard edges and per-pixel noise, so that every
// filter path and value range is exercised.
ImageU8 TestRgb(int w, int h, uint64_t seed) {
  ImageU8 img(w, h, 3);
  Rng rng(seed);
  for (int v = 0; v < h; ++v) {
    for (int u = 0; u < w; ++u) {
      uint8_t* p = img.at(u, v);
      p[0] = static_cast<uint8_t>(u * 255 / std::max(w - 1, 1));
      p[1] = static_cast<uint8_t>(((u / 8 + v / 8) % 2) ? 230 : 20);
      p[2] = static_cast<uint8_t>(rng.NextU64() & 0xff);
    }
  }
  return img;
}

// chunk types of a PNG byte stream, in order.
std::vector<std::string> ChunkTypes(const std::vector<uint8_t>& png) {
  std::vector<std::string> types;
  size_t pos = 8;  // after the signature
  while (pos + 12 <= png.size()) {
    const uint32_t len = (uint32_t{png[pos]} << 24) | (uint32_t{png[pos + 1]} << 16) |
                         (uint32_t{png[pos + 2]} << 8) | uint32_t{png[pos + 3]};
    types.emplace_back(reinterpret_cast<const char*>(&png[pos + 4]), 4);
    pos += 12 + len;
  }
  EXPECT_EQ(pos, png.size()) << "chunk lengths do not add up to the file size";
  return types;
}

TEST(PngIo, Rgb8RoundTripIsExact) {
  TempDir dir;
  const ImageU8 img = TestRgb(37, 23, 1);  // odd sizes: no row alignment assumptions
  const std::string path = (dir.path() / "rgb.png").string();
  WritePngRgb8(path, img);
  const PngImage back = ReadPng(path);
  EXPECT_EQ(back.width, 37);
  EXPECT_EQ(back.height, 23);
  EXPECT_EQ(back.channels, 3);
  EXPECT_EQ(back.bit_depth, 8);
  ASSERT_EQ(back.samples.size(), img.data.size());
  for (size_t i = 0; i < img.data.size(); ++i) {
    ASSERT_EQ(back.samples[i], img.data[i]) << "sample " << i;
  }
}

TEST(PngIo, Gray16RoundTripIsExactIncludingExtremes) {
  TempDir dir;
  ImageU16 img(64, 9, 1);
  Rng rng(2);
  for (auto& s : img.data) s = static_cast<uint16_t>(rng.NextU64() & 0xffff);
  // values that catch byte-order and sign mistakes
  const uint16_t special[] = {0, 1, 255, 256, 0x00ff, 0xff00, 0x7fff, 0x8000, 65534, 65535};
  for (size_t i = 0; i < std::size(special); ++i) img.data[i] = special[i];
  const std::string path = (dir.path() / "gray16.png").string();
  WritePngGray16(path, img);
  const PngImage back = ReadPng(path);
  EXPECT_EQ(back.width, 64);
  EXPECT_EQ(back.height, 9);
  EXPECT_EQ(back.channels, 1);
  EXPECT_EQ(back.bit_depth, 16);
  ASSERT_EQ(back.samples.size(), img.data.size());
  for (size_t i = 0; i < img.data.size(); ++i) {
    ASSERT_EQ(back.samples[i], img.data[i]) << "sample " << i;
  }
}

TEST(PngIo, EveryFilterAndLevelRoundTrips) {
  TempDir dir;
  const ImageU8 img = TestRgb(40, 30, 3);
  for (const char* filter : {"auto", "none", "sub", "up", "avg", "paeth"}) {
    for (int level : {0, 1, 6, 9}) {
      PngEncodeOptions opt;
      opt.filter = filter;
      opt.compression_level = level;
      const std::string path = (dir.path() / "f.png").string();
      WritePngRgb8(path, img, opt);
      const PngImage back = ReadPng(path);
      ASSERT_EQ(back.samples.size(), img.data.size());
      EXPECT_TRUE(std::equal(img.data.begin(), img.data.end(), back.samples.begin()))
          << filter << " level " << level;
    }
  }
}

TEST(PngIo, SameImageGivesSameBytes) {
  TempDir dir;
  const ImageU8 img = TestRgb(64, 48, 4);
  const auto a = EncodePngRgb8(img);
  const auto b = EncodePngRgb8(img);
  EXPECT_EQ(a, b);
  WritePngRgb8((dir.path() / "a.png").string(), img);
  WritePngRgb8((dir.path() / "b.png").string(), img);
  EXPECT_EQ(ReadBytes(dir.path() / "a.png"), a);
  EXPECT_EQ(ReadBytes(dir.path() / "b.png"), a);

  ImageU16 g(31, 17, 1);
  for (size_t i = 0; i < g.data.size(); ++i) g.data[i] = static_cast<uint16_t>(i * 977);
  EXPECT_EQ(EncodePngGray16(g), EncodePngGray16(g));
}

TEST(PngIo, NoTimeOrTextChunks) {
  const auto rgb = EncodePngRgb8(TestRgb(16, 16, 5));
  const auto types = ChunkTypes(rgb);
  ASSERT_GE(types.size(), 4u);
  EXPECT_EQ(types.front(), "IHDR");
  EXPECT_EQ(types[1], "sRGB");
  EXPECT_EQ(types.back(), "IEND");
  for (const auto& t : types) {
    EXPECT_TRUE(t == "IHDR" || t == "sRGB" || t == "IDAT" || t == "IEND") << "chunk " << t;
  }
  ImageU16 g(8, 8, 1, 1234);
  for (const auto& t : ChunkTypes(EncodePngGray16(g))) {
    EXPECT_TRUE(t == "IHDR" || t == "IDAT" || t == "IEND") << "chunk " << t;
  }
}

TEST(PngIo, BadImagesThrow) {
  ImageU8 two_channels(4, 4, 2);
  EXPECT_THROW(EncodePngRgb8(two_channels), Error);
  EXPECT_THROW(EncodePngRgb8(ImageU8()), Error);
  ImageU8 short_data(4, 4, 3);
  short_data.data.pop_back();
  EXPECT_THROW(EncodePngRgb8(short_data), Error);
  EXPECT_THROW(EncodePngGray16(ImageU16(4, 4, 3)), Error);
}

TEST(PngIo, BadOptionsThrowConfigError) {
  PngEncodeOptions opt;
  opt.compression_level = 10;
  EXPECT_THROW(opt.ValidateOrThrow(), ConfigError);
  opt.compression_level = 1;
  opt.filter = "fast";
  EXPECT_THROW(opt.ValidateOrThrow(), ConfigError);
  EXPECT_THROW(EncodePngRgb8(TestRgb(4, 4, 6), opt), ConfigError);
}

TEST(PngIo, WriteErrorNamesThePath) {
  TempDir dir;
  const std::string path = (dir.path() / "missing_folder" / "x.png").string();
  try {
    WritePngRgb8(path, TestRgb(4, 4, 7));
    FAIL() << "expected an Error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
  }
}

TEST(PngIo, ReadErrorsNameThePath) {
  TempDir dir;
  const std::string missing = (dir.path() / "nope.png").string();
  try {
    ReadPng(missing);
    FAIL() << "expected an Error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(missing), std::string::npos) << e.what();
  }
  const auto not_png = dir.path() / "text.png";
  std::ofstream(not_png) << "hello, this is not a PNG file";
  EXPECT_THROW(ReadPng(not_png.string()), Error);

  // a truncated PNG fails cleanly (libpng error -> Error, no crash)
  auto bytes = EncodePngRgb8(TestRgb(32, 32, 8));
  bytes.resize(bytes.size() / 2);
  const auto truncated = dir.path() / "truncated.png";
  {
    std::ofstream f(truncated, std::ios::binary);
    f.write(reinterpret_cast<const char*>(bytes.data()),
            static_cast<std::streamsize>(bytes.size()));
  }
  EXPECT_THROW(ReadPng(truncated.string()), Error);
}

}  // namespace
}  // namespace penumbra
