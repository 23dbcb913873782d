#pragma once
// crash-safe output files. every finished file of a run (PNG, JSON, PCD, YAML, the composed
// MJCF) is written whole to a temporary name in its own folder and renamed into place, so a
// file under its final name is always complete, even after SIGKILL or a full disk. streaming
// CSVs (one row per step or sample) cannot be renamed per row; LineFile hands the kernel
// whole rows only, and on a failed write cuts the file back to its last complete row.
//
// links: files are created with O_NOFOLLOW and O_EXCL (temporaries) and folders are checked
// with lstat, so an output never writes through a symbolic link.
//
// errors name the path and the system's reason (e.g. "No space left on device").

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>

namespace penumbra {

/// true for the temporary names WriteFileAtomic uses (".<name>.tmp-<pid>-<n>"): what a
/// killed writer can leave behind.
bool IsTemporaryOutputName(const std::string& file_name);

/// writes `bytes` to `path`: to a temporary file in the same folder (O_CREAT | O_EXCL |
/// O_NOFOLLOW), then rename(2) over `path` (atomic on POSIX file systems; an existing file
/// or link of that name is replaced, never written through). no fsync: the file survives
/// the process being killed, not a power loss.
/// @throws Error naming `path` and the reason (cannot create, short write, cannot rename);
///         the temporary file is removed and `path` is left as it was.
void WriteFileAtomic(const std::filesystem::path& path, std::string_view bytes);

/// the 64-bit FNV-1a hash of `bytes` (Fowler, Noll, Vo; offset basis 14695981039346656037,
/// prime 1099511628211): names cache files by their content.
uint64_t Fnv1a64(std::string_view bytes);

/// a content-named cache file: writes `bytes` to dir / "<stem>-<16 hex digits of
/// Fnv1a64(bytes)><ext>" (WriteFileAtomic) unless a file of that name and size is already
/// there, and returns its path. `dir` must exist.
/// @throws Error as WriteFileAtomic.
std::string WriteContentNamedFile(const std::filesystem::path& dir, const std::string& stem,
                                  const std::string& ext, std::string_view bytes);

/// creates the folder root / rel and its missing parents. `root` (the output folder the user
/// named) is taken as given and may itself be a link; every component of `rel` below it must
/// be a real folder (lstat), so that nothing is written through a link inside the root.
/// @throws Error naming the folder if it cannot be created, a component of `rel` is a
///         symbolic link, a file, empty, "." or "..".
void CreateOutputFolder(const std::filesystem::path& root, const std::filesystem::path& rel = {});

/// a file written as whole lines (CSV rows): Append() buffers rows, which reach the kernel
/// only as whole rows (one write(2) of complete rows at a time), so a killed process leaves
/// complete rows at worst. a write that fails part-way (full disk) is cut back to the last
/// complete row that reached the file (ftruncate) and reported; a file that holds no
/// complete row then is removed.
class LineFile {
 public:
  LineFile() = default;
  /// creates or truncates `path` (O_NOFOLLOW: a link of that name is an error).
  /// `buffer_bytes`: rows kept in memory before a write; 0 writes every Append at once.
  /// @throws Error naming the path if it cannot be created.
  explicit LineFile(std::filesystem::path path, size_t buffer_bytes = 1 << 16);
  LineFile(LineFile&& other) noexcept;
  LineFile& operator=(LineFile&& other) noexcept;
  LineFile(const LineFile&) = delete;
  LineFile& operator=(const LineFile&) = delete;
  /// closes the file; rows still buffered are written (errors are dropped: call Close()
  /// to see them).
  ~LineFile();

  /// appends `rows` (one or more complete lines, each ending in '\n').
  /// @throws Error naming the path if the buffer had to be written and that failed, if the
  ///         file is closed or failed earlier, or if `rows` does not end in '\n'.
  void Append(std::string_view rows);
  /// writes the buffered rows.
  /// @throws Error as Append.
  void Flush();
  /// flushes and closes; a closed or never-opened file is a no-op.
  /// @throws Error as Append.
  void Close();

  bool is_open() const { return fd_ >= 0; }
  const std::filesystem::path& path() const { return path_; }

 private:
  void WriteBuffer();
  [[noreturn]] void Fail(int err);

  std::filesystem::path path_;
  int fd_ = -1;
  size_t buffer_bytes_ = 0;
  std::string buffer_;
  size_t written_ = 0;  ///< bytes of complete rows in the file
  std::string failure_;
};

}  // namespace penumbra
