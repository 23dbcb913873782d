#include "penumbra/compose/mjcf_text.h"

#include <cctype>
#include <charconv>
#include <cstdlib>
#include <filesystem>
#include <system_error>

namespace penumbra::compose {

std::optional<std::vector<double>> ParseNumbers(const std::string& text) {
  std::vector<double> out;
  const char* p = text.c_str();
  while (true) {
    while (*p != '\0' && std::isspace(static_cast<unsigned char>(*p))) ++p;
    if (*p == '\0') break;
    char* end = nullptr;
    const double v = std::strtod(p, &end);
    if (end == p || (*end != '\0' && !std::isspace(static_cast<unsigned char>(*end)))) {
      return std::nullopt;
    }
    out.push_back(v);
    p = end;
  }
  return out;
}

std::string FormatNumbers(const std::vector<double>& values) {
  std::string out;
  char buf[64];
  for (size_t i = 0; i < values.size(); ++i) {
    // -0 prints as "-0", which reads back fine; keep it simple and exact
    const auto res = std::to_chars(buf, buf + sizeof(buf), values[i]);
    if (i > 0) out += ' ';
    out.append(buf, res.ptr);
  }
  return out;
}

bool IsAbsolutePath(const std::string& path) { return !path.empty() && path[0] == '/'; }

std::string DirName(const std::string& path) {
  const size_t slash = path.find_last_of('/');
  if (slash == std::string::npos) return "";
  return path.substr(0, slash + 1);
}

std::string JoinPath(const std::string& dir, const std::string& rel) {
  if (dir.empty() || IsAbsolutePath(rel)) return rel;
  if (dir.back() == '/') return dir + rel;
  return dir + "/" + rel;
}

std::string NormalizePath(const std::string& path) {
  std::error_code ec;
  std::filesystem::path p = std::filesystem::absolute(std::filesystem::path(path), ec);
  if (ec) p = std::filesystem::path(path);
  return p.lexically_normal().string();
}

std::string StripPath(const std::string& path) {
  const size_t slash = path.find_last_of("/\\");
  return slash == std::string::npos ? path : path.substr(slash + 1);
}

bool FileExists(const std::string& path) {
  std::error_code ec;
  return std::filesystem::is_regular_file(std::filesystem::path(path), ec);
}

std::string ToLower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

}  // namespace penumbra::compose
