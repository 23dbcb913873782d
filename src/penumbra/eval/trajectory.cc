#include "penumbra/eval/trajectory.h"

#include <fmt/format.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstring>
#include <optional>

#include "penumbra/core/error.h"
#include "penumbra/core/input_file.h"
#include "penumbra/core/text_match.h"

namespace penumbra {
namespace {

constexpr std::array<const char*, 8> kFieldNames = {"timestamp", "tx", "ty", "tz",
                                                    "qx",        "qy", "qz", "qw"};
constexpr char kExpectedLine[] =
    "expected 8 numbers 'timestamp tx ty tz qx qy qz qw' separated by spaces, tabs or commas";

bool IsSeparator(char c) { return c == ' ' || c == '\t' || c == ',' || c == '\r'; }

// the fields of one line, split at runs of separators
std::vector<std::string_view> SplitFields(std::string_view line) {
  std::vector<std::string_view> fields;
  size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && IsSeparator(line[i])) ++i;
    const size_t start = i;
    while (i < line.size() && !IsSeparator(line[i])) ++i;
    if (i > start) fields.push_back(line.substr(start, i - start));
  }
  return fields;
}

// a byte that has no place in a text file: NUL and the control characters other than tab,
// line feed and carriage return
bool IsBinaryByte(unsigned char c) {
  return (c < 0x20 && c != '\t' && c != '\n' && c != '\r') || c == 0x7f;
}

// checks the bytes of the text that one line (without its '\n') holds: "" or the problem
std::string LineProblem(std::string_view line) {
  for (size_t i = 0; i < line.size(); ++i)
    if (IsBinaryByte(static_cast<unsigned char>(line[i])))
      return fmt::format(
          "column {} holds the byte 0x{:02x}, not text ('{}'): binary data; "
          "expected a TUM text file of lines 'timestamp tx ty tz qx qy qz qw'",
          i + 1, static_cast<unsigned char>(line[i]), SanitizeForMessage(line.substr(0, 32), 32));
  if (line.size() > kTumMaxLineBytes)
    return fmt::format(
        "line of more than {} bytes ('{}...'); expected a TUM text file of lines "
        "'timestamp tx ty tz qx qy qz qw'",
        kTumMaxLineBytes, SanitizeForMessage(line.substr(0, 32), 32));
  return "";
}

}  // namespace

Eigen::Matrix3Xd Trajectory::Positions() const {
  Eigen::Matrix3Xd p(3, static_cast<Eigen::Index>(X_WB.size()));
  for (size_t i = 0; i < X_WB.size(); ++i)
    p.col(static_cast<Eigen::Index>(i)) = X_WB[i].translation();
  return p;
}

Trajectory ParseTumTrajectory(std::string_view text, const std::string& source) {
  if (text.size() > kTumMaxFileBytes)
    throw ConfigError(source, 0, "",
                      fmt::format("{} bytes; expected a TUM trajectory of at most {} bytes",
                                  text.size(), kTumMaxFileBytes));
  Trajectory t;
  int line_number = 0;
  int previous_line = 0;
  size_t pos = 0;
  while (pos < text.size()) {
    const size_t end = std::min(text.find('\n', pos), text.size());
    const std::string_view line = text.substr(pos, end - pos);
    pos = end + 1;
    ++line_number;
    if (const std::string bad = LineProblem(line); !bad.empty())
      throw ConfigError(source, line_number, "", bad);
    const std::vector<std::string_view> fields = SplitFields(line);
    if (fields.empty() || fields.front().front() == '#') continue;
    if (fields.size() != kFieldNames.size())
      throw ConfigError(source, line_number, "",
                        fmt::format("{} field{}; {}", fields.size(), fields.size() == 1 ? "" : "s",
                                    kExpectedLine));
    std::array<double, 8> v{};
    for (size_t k = 0; k < fields.size(); ++k) {
      const std::optional<double> x = ParseDecimal(fields[k]);
      if (!x)
        throw ConfigError(
            source, line_number, "",
            fmt::format("field {} ({}) '{}' is not a finite decimal number; {}", k + 1,
                        kFieldNames[k], SanitizeForMessage(fields[k], 64), kExpectedLine));
      v[k] = *x;
    }
    // finite is not enough: 1e308 squares to infinity in every error metric
    if (!(std::abs(v[0]) <= kTumMaxAbsTimestampSec))
      throw ConfigError(source, line_number, "",
                        fmt::format("timestamp {} is beyond +-{:g} s; expected seconds (Unix "
                                    "time or time since the start)",
                                    v[0], kTumMaxAbsTimestampSec));
    for (size_t k = 1; k <= 3; ++k)
      if (!(std::abs(v[k]) <= kTumMaxAbsCoordinateM))
        throw ConfigError(source, line_number, "",
                          fmt::format("field {} ({}) {} is beyond +-{:g} m; expected a position "
                                      "in metres (docs/evaluation.md \"Input limits\")",
                                      k + 1, kFieldNames[k], v[k], kTumMaxAbsCoordinateM));
    // quaternion: file order x y z w
    const Eigen::Quaterniond q(v[7], v[4], v[5], v[6]);
    const double norm = q.norm();
    if (!(std::abs(norm - 1.0) <= kTumQuaternionNormTolerance))
      throw ConfigError(source, line_number, "",
                        fmt::format("quaternion (qx qy qz qw) = ({} {} {} {}) has norm {:.6g}; "
                                    "expected a unit quaternion (norm within {} of 1), the scalar "
                                    "qw last",
                                    v[4], v[5], v[6], v[7], norm, kTumQuaternionNormTolerance));
    if (!t.empty() && !(v[0] > t.time_sec.back()))
      throw ConfigError(source, line_number, "",
                        fmt::format("timestamp {} is not after the previous pose's {} (line {}); "
                                    "expected strictly increasing timestamps",
                                    v[0], t.time_sec.back(), previous_line));
    Pose X = Pose::Identity();
    X.linear() = q.normalized().toRotationMatrix();
    X.translation() = Eigen::Vector3d(v[1], v[2], v[3]);
    t.time_sec.push_back(v[0]);
    t.X_WB.push_back(X);
    previous_line = line_number;
  }
  if (t.empty())
    throw ConfigError(source, 0, "",
                      fmt::format("no poses ({} line{}, all blank or comments); expected lines "
                                  "'timestamp tx ty tz qx qy qz qw'",
                                  line_number, line_number == 1 ? "" : "s"));
  return t;
}

Trajectory ReadTumTrajectory(const std::filesystem::path& path) {
  // a regular file only: a FIFO blocked in open() for ever, a folder or device is refused
  // naming what it is
  const InputFile file = OpenInputFile(path, "TUM trajectory file");
  // read in blocks, each checked as it arrives: a device, pipe or huge binary file is refused
  // at its first bad byte or line, before more than a block past the limit is held
  std::string text;
  std::array<char, 1 << 16> block;
  int line = 1;
  size_t line_start = 0;
  while (true) {
    const ssize_t got = ::read(file.fd.get(), block.data(), block.size());
    if (got < 0 && errno == EINTR) continue;
    if (got < 0)
      throw ConfigError(
          path.string(), 0, "",
          fmt::format("read failed ({}); expected a TUM trajectory file", std::strerror(errno)));
    const size_t n = static_cast<size_t>(got);
    if (n == 0) break;
    if (text.size() + n > kTumMaxFileBytes)
      throw ConfigError(path.string(), line, "",
                        fmt::format("more than {} bytes; expected a TUM trajectory file of at "
                                    "most {} bytes (docs/evaluation.md \"Input limits\")",
                                    kTumMaxFileBytes, kTumMaxFileBytes));
    const size_t from = text.size();
    text.append(block.data(), n);
    for (size_t i = from; i < text.size(); ++i) {
      if (text[i] == '\n') {
        if (const std::string bad =
                LineProblem(std::string_view(text).substr(line_start, i - line_start));
            !bad.empty())
          throw ConfigError(path.string(), line, "", bad);
        ++line;
        line_start = i + 1;
      }
    }
    const std::string_view open_line = std::string_view(text).substr(line_start);
    if (const std::string bad = LineProblem(open_line.substr(0, kTumMaxLineBytes + 1));
        !bad.empty())
      throw ConfigError(path.string(), line, "", bad);
  }
  return ParseTumTrajectory(text, path.string());
}

std::string FormatTumTrajectory(const Trajectory& trajectory) {
  std::string out = "# timestamp tx ty tz qx qy qz qw\n";
  for (size_t i = 0; i < trajectory.size(); ++i) {
    const Eigen::Vector3d p = trajectory.X_WB[i].translation();
    const Eigen::Quaterniond q(trajectory.X_WB[i].linear());
    out += fmt::format("{} {} {} {} {} {} {} {}\n", trajectory.time_sec[i], p.x(), p.y(), p.z(),
                       q.x(), q.y(), q.z(), q.w());
  }
  return out;
}

}  // namespace penumbra
