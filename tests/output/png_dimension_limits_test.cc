// a PNG's declared size is checked before its rows are allocated: a 60-byte file that
// declares 20000 x 20000 or 1000000 x 1000000 pixels is refused with a message naming it (the
// reader allocated width x height x channels first and died of std::bad_alloc), and the same
// caps hold for the header peek that guards OpenCV's decoders (core/image_file_limits.h).

#include <gtest/gtest.h>
#include <zlib.h>

#include <string>

#include "common/temp_dir.h"
#include "penumbra/core/error.h"
#include "penumbra/core/image_file_limits.h"
#include "penumbra/output/png_io.h"

namespace penumbra {
namespace {

void PngLimitsPutBe32(std::string* b, uint32_t v) {
  for (int s = 24; s >= 0; s -= 8) b->push_back(static_cast<char>((v >> s) & 0xff));
}

void PngLimitsChunk(std::string* png, const char* type, const std::string& data) {
  PngLimitsPutBe32(png, static_cast<uint32_t>(data.size()));
  const std::string body = std::string(type, 4) + data;
  *png += body;
  PngLimitsPutBe32(png, static_cast<uint32_t>(
                            crc32(0, reinterpret_cast<const Bytef*>(body.data()), body.size())));
}

// an 8-bit RGB PNG that declares width x height and holds one empty IDAT
std::string PngLimitsDeclaring(uint32_t width, uint32_t height) {
  std::string png("\x89PNG\r\n\x1a\n", 8);
  std::string ihdr;
  PngLimitsPutBe32(&ihdr, width);
  PngLimitsPutBe32(&ihdr, height);
  ihdr += std::string("\x08\x02\x00\x00\x00", 5);
  PngLimitsChunk(&png, "IHDR", ihdr);
  PngLimitsChunk(&png, "IDAT", std::string("\x78\x9c\x03\x00\x00\x00\x00\x01", 8));
  PngLimitsChunk(&png, "IEND", "");
  return png;
}

std::string PngLimitsReadError(const std::string& path) {
  try {
    ReadPng(path);
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

TEST(PngDimensionLimits, HugeDeclaredSizesAreRefusedBeforeAllocating) {
  testing::TempDir tmp;
  const std::string big = tmp.Write("big.png", PngLimitsDeclaring(20000, 20000));
  std::string err = PngLimitsReadError(big);
  EXPECT_NE(err.find("cannot read PNG '" + big +
                     "': PNG of 20000 x 20000 pixels; expected 1 to "
                     "32768 pixels a side and at most 134217728 pixels"),
            std::string::npos)
      << err;
  const std::string huge = tmp.Write("huge.png", PngLimitsDeclaring(1000000, 1000000));
  err = PngLimitsReadError(huge);
  EXPECT_NE(err.find("cannot read PNG '" + huge + "'"), std::string::npos) << err;
  // libpng's own check (its user limit is set to the side cap) refuses it while reading IHDR
  // the header peek used before OpenCV decodes a file
  try {
    CheckImageFileSize(big);
    ADD_FAILURE() << "20000 x 20000 passed";
  } catch (const ConfigError& e) {
    EXPECT_EQ(e.file(), big);
    EXPECT_NE(std::string(e.what()).find("PNG of 20000 x 20000 pixels"), std::string::npos);
  }
  EXPECT_NO_THROW(CheckImageFileSize(tmp.Write("ok.png", PngLimitsDeclaring(640, 480))));
}

TEST(PngDimensionLimits, JpegFrameHeadersArePeekedToo) {
  // SOI, an APP0 segment of 16 bytes, then SOF0: precision 8, height 40000, width 50000
  std::string jpeg("\xff\xd8\xff\xe0\x00\x10JFIF\x00\x01\x01\x00\x00\x01\x00\x01\x00\x00", 20);
  jpeg += std::string("\xff\xc0\x00\x11\x08\x9c\x40\xc3\x50\x03", 10);
  const std::optional<ImageFileSize> size = PeekImageFileSize(jpeg);
  ASSERT_TRUE(size);
  EXPECT_EQ(size->width, 50000u);
  EXPECT_EQ(size->height, 40000u);
  EXPECT_THROW(CheckImageBytesSize(jpeg, "texture.jpg"), ConfigError);
  EXPECT_FALSE(PeekImageFileSize("GIF89a...."));
  EXPECT_NO_THROW(CheckImageBytesSize("GIF89a....", "x.gif"));
}

}  // namespace
}  // namespace penumbra
