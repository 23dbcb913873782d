#pragma once
// a fresh, uniquely named scratch folder for one test, and reading back the files a
// test wrote. ctest runs every test case as its own process, in parallel, so a fixed
// name under ::testing::TempDir() is shared between processes and races.

#include <gtest/gtest.h>
#include <stdlib.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace penumbra::testing {

/// an empty folder made with mkdtemp under the system temp dir; it and
/// everything in it are removed at destruction.
class TempDir {
 public:
  TempDir() {
    std::string tmpl = (std::filesystem::temp_directory_path() / "penumbra_test_XXXXXX").string();
    if (mkdtemp(tmpl.data()) == nullptr) throw std::runtime_error("mkdtemp failed: " + tmpl);
    path_ = tmpl;
  }
  ~TempDir() {
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;

  const std::filesystem::path& path() const { return path_; }
  std::string str() const { return path_.string(); }

  /// writes `text` to <dir>/<rel> (creating folders) and returns the absolute path.
  std::string Write(const std::string& rel, const std::string& text) const {
    const std::filesystem::path p = path_ / rel;
    std::filesystem::create_directories(p.parent_path());
    std::ofstream(p, std::ios::binary) << text;
    return p.string();
  }

 private:
  std::filesystem::path path_;
};

/// the whole content of file `p` ("" when it cannot be read).
inline std::string ReadAll(const std::filesystem::path& p) {
  std::ifstream f(p, std::ios::binary);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

/// the bytes of file `p` (empty when it cannot be read).
inline std::vector<uint8_t> ReadBytes(const std::filesystem::path& p) {
  std::ifstream f(p, std::ios::binary);
  return std::vector<uint8_t>(std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>());
}

/// a TempDir that lives as long as the test process: a drop-in for
/// ::testing::TempDir() whose files no other test process can see.
inline const std::string& ProcessTempDir() {
  static const TempDir dir;
  static const std::string path = dir.str();
  return path;
}

}  // namespace penumbra::testing
