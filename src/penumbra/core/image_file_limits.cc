#include "penumbra/core/image_file_limits.h"

#include <fmt/format.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <filesystem>

#include "penumbra/core/error.h"
#include "penumbra/core/input_file.h"

namespace penumbra {
namespace {

uint32_t BigEndian32(std::string_view b, size_t at) {
  return (uint32_t(uint8_t(b[at])) << 24) | (uint32_t(uint8_t(b[at + 1])) << 16) |
         (uint32_t(uint8_t(b[at + 2])) << 8) | uint32_t(uint8_t(b[at + 3]));
}
uint32_t BigEndian16(std::string_view b, size_t at) {
  return (uint32_t(uint8_t(b[at])) << 8) | uint32_t(uint8_t(b[at + 1]));
}

constexpr std::string_view kPngSignature("\x89PNG\r\n\x1a\n", 8);

}  // namespace

std::optional<ImageFileSize> PeekImageFileSize(std::string_view b) {
  // PNG: signature, then the IHDR chunk (length 13, "IHDR", width, height, ...)
  if (b.substr(0, 8) == kPngSignature) {
    if (b.size() < 26 || b.substr(12, 4) != "IHDR") return std::nullopt;
    return ImageFileSize{BigEndian32(b, 16), BigEndian32(b, 20), uint8_t(b[24]), uint8_t(b[25])};
  }
  // JPEG: SOI, then segments (0xff, marker, 16-bit length including itself) up to the first
  // start of frame (SOF0..SOF15 less DHT c4, JPG c8 and DAC cc): precision, height, width
  if (b.size() < 4 || uint8_t(b[0]) != 0xff || uint8_t(b[1]) != 0xd8) return std::nullopt;
  size_t at = 2;
  while (at + 4 <= b.size()) {
    if (uint8_t(b[at]) != 0xff) return std::nullopt;
    const uint8_t marker = uint8_t(b[at + 1]);
    if (marker == 0xff) {  // fill byte
      ++at;
      continue;
    }
    if (marker == 0xd8 || (marker >= 0xd0 && marker <= 0xd7) || marker == 0x01) {
      at += 2;  // markers without a length
      continue;
    }
    const uint32_t length = BigEndian16(b, at + 2);
    if (length < 2) return std::nullopt;
    const bool sof =
        marker >= 0xc0 && marker <= 0xcf && marker != 0xc4 && marker != 0xc8 && marker != 0xcc;
    if (sof) {
      if (at + 9 > b.size()) return std::nullopt;
      return ImageFileSize{BigEndian16(b, at + 7), BigEndian16(b, at + 5)};
    }
    if (marker == 0xda || marker == 0xd9) return std::nullopt;  // scan or end before a frame
    at += 2 + length;
  }
  return std::nullopt;
}

std::string ImageFileSizeProblem(const ImageFileSize& s, std::string_view format) {
  if (s.width == 0 || s.height == 0 || s.width > kMaxImageFileSide ||
      s.height > kMaxImageFileSide || uint64_t{s.width} * s.height > kMaxImageFilePixels)
    return fmt::format(
        "{} of {} x {} pixels; expected 1 to {} pixels a side and at most {} pixels "
        "(docs/datasets.md \"Input limits\")",
        format, s.width, s.height, kMaxImageFileSide, kMaxImageFilePixels);
  return "";
}

void CheckImageBytesSize(std::string_view bytes, const std::string& what) {
  const std::optional<ImageFileSize> size = PeekImageFileSize(bytes);
  if (!size) return;
  const std::string bad =
      ImageFileSizeProblem(*size, bytes.substr(0, 8) == kPngSignature ? "PNG" : "JPEG");
  if (!bad.empty()) throw ConfigError(what, 0, "", bad);
}

void CheckImageFileSize(const std::filesystem::path& path) {
  // a regular file only: a FIFO blocked in open() for ever, a device never ends
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) return;  // left to the decoder, which names it
  const InputFile f = OpenInputFile(path, "image file");
  std::string head(1 << 16, '\0');
  size_t have = 0;
  while (have < head.size()) {
    const ssize_t n = ::read(f.fd.get(), head.data() + have, head.size() - have);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) break;
    have += static_cast<size_t>(n);
  }
  head.resize(have);
  CheckImageBytesSize(head, path.string());
}

}  // namespace penumbra
