#include "penumbra/core/output_file.h"

#include <errno.h>
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cstdio>
#include <cstring>
#include <utility>

#include "penumbra/core/error.h"

namespace penumbra {
namespace {

namespace fs = std::filesystem;

std::string Reason(int err) { return std::strerror(err); }

// writes all of `data` to fd; returns 0 or the errno of the failed write.
// `done` counts the bytes written (also on failure).
int WriteAll(int fd, const char* data, size_t n, size_t* done) {
  *done = 0;
  while (*done < n) {
    const ssize_t w = ::write(fd, data + *done, n - *done);
    if (w < 0) {
      if (errno == EINTR) continue;
      return errno;
    }
    if (w == 0) return EIO;
    *done += static_cast<size_t>(w);
  }
  return 0;
}

constexpr std::string_view kTmpMarker = ".tmp-";

}  // namespace

bool IsTemporaryOutputName(const std::string& name) {
  return name.size() > 1 && name.front() == '.' && name.find(kTmpMarker) != std::string::npos;
}

void WriteFileAtomic(const fs::path& path, std::string_view bytes) {
  static std::atomic<uint64_t> counter{0};
  const fs::path tmp =
      path.parent_path() / ("." + path.filename().string() + std::string(kTmpMarker) +
                            std::to_string(::getpid()) + "-" + std::to_string(counter++));
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0644);
  if (fd < 0) throw Error("cannot write '" + path.string() + "': " + Reason(errno));
  size_t done = 0;
  int err = WriteAll(fd, bytes.data(), bytes.size(), &done);
  if (::close(fd) != 0 && err == 0) err = errno;
  if (err == 0 && ::rename(tmp.c_str(), path.c_str()) != 0) err = errno;
  if (err != 0) {
    ::unlink(tmp.c_str());
    throw Error("cannot write '" + path.string() + "': " + Reason(err));
  }
}

void CreateOutputFolder(const fs::path& root, const fs::path& rel) {
  std::error_code ec;
  fs::create_directories(root, ec);
  if (ec || !fs::is_directory(root))
    throw Error("cannot create output folder '" + root.string() +
                "': " + (ec ? ec.message() : std::string("a file of that name exists")));
  fs::path p = root;
  for (const fs::path& part : rel) {
    if (part.empty() || part == "." || part == "..")
      throw Error("output folder '" + (root / rel).string() + "': bad component '" + part.string() +
                  "'");
    p /= part;
    if (::mkdir(p.c_str(), 0755) == 0) continue;
    const int err = errno;
    struct stat st;
    if (err != EEXIST || ::lstat(p.c_str(), &st) != 0)
      throw Error("cannot create output folder '" + p.string() + "': " + Reason(err));
    if (S_ISLNK(st.st_mode))
      throw Error("cannot write into '" + p.string() +
                  "': it is a symbolic link; outputs are never written through links");
    if (!S_ISDIR(st.st_mode))
      throw Error("cannot create output folder '" + p.string() + "': a file of that name exists");
  }
}

LineFile::LineFile(fs::path path, size_t buffer_bytes)
    : path_(std::move(path)), buffer_bytes_(buffer_bytes) {
  fd_ = ::open(path_.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_NOFOLLOW | O_CLOEXEC, 0644);
  if (fd_ < 0) {
    const int err = errno;
    throw Error("cannot write '" + path_.string() +
                "': " + (err == ELOOP ? std::string("it is a symbolic link") : Reason(err)));
  }
}

LineFile::LineFile(LineFile&& o) noexcept
    : path_(std::move(o.path_)),
      fd_(std::exchange(o.fd_, -1)),
      buffer_bytes_(o.buffer_bytes_),
      buffer_(std::move(o.buffer_)),
      written_(o.written_),
      failure_(std::move(o.failure_)) {}

LineFile& LineFile::operator=(LineFile&& o) noexcept {
  if (this != &o) {
    try {
      Close();
    } catch (...) {
    }
    path_ = std::move(o.path_);
    fd_ = std::exchange(o.fd_, -1);
    buffer_bytes_ = o.buffer_bytes_;
    buffer_ = std::move(o.buffer_);
    written_ = o.written_;
    failure_ = std::move(o.failure_);
  }
  return *this;
}

LineFile::~LineFile() {
  try {
    Close();
  } catch (...) {
  }
}

void LineFile::Append(std::string_view rows) {
  if (!failure_.empty()) throw Error(failure_);
  if (fd_ < 0) throw Error("cannot write '" + path_.string() + "': the file is closed");
  if (rows.empty()) return;
  if (rows.back() != '\n')
    throw Error("LineFile '" + path_.string() + "': appended text does not end with a newline");
  buffer_.append(rows);
  if (buffer_.size() >= buffer_bytes_) WriteBuffer();
}

void LineFile::Flush() {
  if (!failure_.empty()) throw Error(failure_);
  if (fd_ >= 0 && !buffer_.empty()) WriteBuffer();
}

void LineFile::Close() {
  if (fd_ < 0) {
    if (!failure_.empty()) throw Error(failure_);
    return;
  }
  Flush();
  const int fd = std::exchange(fd_, -1);
  if (::close(fd) != 0) {
    failure_ = "cannot write '" + path_.string() + "': " + Reason(errno);
    throw Error(failure_);
  }
}

void LineFile::WriteBuffer() {
  size_t done = 0;
  const int err = WriteAll(fd_, buffer_.data(), buffer_.size(), &done);
  if (err != 0) {
    // keep the complete rows that made it to the file
    const size_t last_newline = std::string_view(buffer_.data(), done).rfind('\n');
    if (last_newline != std::string_view::npos) written_ += last_newline + 1;
    Fail(err);
  }
  written_ += buffer_.size();
  buffer_.clear();
}

void LineFile::Fail(int err) {
  // cut a partial row (and anything after the last complete row) off the file; a file
  // that has no complete row is removed
  const int fd = std::exchange(fd_, -1);
  struct stat st;
  const bool regular = ::fstat(fd, &st) == 0 && S_ISREG(st.st_mode);
  if (!regular) {
    ::close(fd);  // a device (e.g. /dev/full): nothing to cut or remove
  } else if (written_ == 0) {
    ::close(fd);
    ::unlink(path_.c_str());
  } else {
    if (::ftruncate(fd, static_cast<off_t>(written_)) != 0) {
      // nothing better to do: the error below is what is reported
    }
    ::close(fd);
  }
  buffer_.clear();
  failure_ = "cannot write '" + path_.string() + "': " + Reason(err);
  throw Error(failure_);
}

uint64_t Fnv1a64(std::string_view bytes) {
  uint64_t h = 14695981039346656037ull;
  for (const unsigned char c : bytes) {
    h ^= c;
    h *= 1099511628211ull;
  }
  return h;
}

std::string WriteContentNamedFile(const std::filesystem::path& dir, const std::string& stem,
                                  const std::string& ext, std::string_view bytes) {
  char hex[17];
  std::snprintf(hex, sizeof(hex), "%016llx", static_cast<unsigned long long>(Fnv1a64(bytes)));
  const std::filesystem::path p = dir / (stem + "-" + hex + ext);
  std::error_code ec;
  if (std::filesystem::is_regular_file(p, ec) && std::filesystem::file_size(p, ec) == bytes.size())
    return p.string();
  WriteFileAtomic(p, bytes);
  return p.string();
}

}  // namespace penumbra
