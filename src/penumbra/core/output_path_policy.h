#pragma once
// the one rule for files that a client of a running simulation names (start_recording over
// ZeroMQ, the viewer's record button, ROS services: every command that writes goes through
// OpenNewFileInside). a client may create a NEW file INSIDE the run's output folder and nowhere
// else:
//   - the path is relative to the output folder (no leading '/'), at most 1024 bytes, with no
//     control characters (bytes below 0x20 and 0x7f) and no empty, "." or ".." component;
//   - it ends in the required extension (".plog" for run logs) with a name before it;
//   - every folder on the way must already exist and be a real folder: the walk opens each
//     with openat(O_DIRECTORY | O_NOFOLLOW), so a symbolic link anywhere below the output
//     folder is refused and nothing can be swapped in between the check and the use;
//   - the file is created with O_CREAT | O_EXCL | O_NOFOLLOW: an existing file (or link) of
//     that name is never overwritten or followed.
// the output folder itself is taken as the user gave it (it may be a link the user made).
//
// errors name the path as the client gave it (escaped) and the rule it broke; they never name
// the output folder's absolute path, so that a client learns nothing about the server's disk.
//
// the read side (ReadExistingFileInside: set_adversity's preset files) has the same rules for
// the path, applied to a folder the caller names (the world file's folder): the path is
// relative, has no "..", "." or empty component, ends in the required extension, every
// folder on the way and the file itself are opened with O_NOFOLLOW (a symbolic link anywhere
// below the folder is refused), the file must be a regular file (no FIFO or device: opened
// with O_NONBLOCK, then checked) of at most a given size, read whole.

#include <filesystem>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

#include "penumbra/core/error.h"

namespace penumbra {

/// a file descriptor that closes itself (move-only).
class UniqueFd {
 public:
  UniqueFd() = default;
  explicit UniqueFd(int fd) : fd_(fd) {}
  UniqueFd(UniqueFd&& other) noexcept : fd_(other.release()) {}
  UniqueFd& operator=(UniqueFd&& other) noexcept;
  UniqueFd(const UniqueFd&) = delete;
  UniqueFd& operator=(const UniqueFd&) = delete;
  ~UniqueFd();

  /// the descriptor (-1 = none).
  int get() const { return fd_; }
  /// hands the descriptor over (the caller closes it); this object holds none after.
  int release() {
    const int fd = fd_;
    fd_ = -1;
    return fd;
  }

 private:
  int fd_ = -1;
};

/// a client path refused by OpenNewFileInside: what() is "output path '<path>': <rule>;
/// expected ...".
class OutputPathError : public Error {
 public:
  OutputPathError(const std::string& client_path, const std::string& rule,
                  std::string_view required_extension);
  /// the path as the client gave it (unescaped).
  const std::string& client_path() const { return client_path_; }
  /// the rule it broke, e.g. "is absolute (starts with '/')".
  const std::string& rule() const { return rule_; }

 private:
  std::string client_path_;
  std::string rule_;
};

/// a file created by OpenNewFileInside.
struct NewOutputFile {
  UniqueFd fd;                 ///< open for writing (O_WRONLY | O_CLOEXEC), empty (0 bytes)
  UniqueFd folder;             ///< the folder that holds it (O_DIRECTORY): for unlinkat
  std::string name;            ///< its name in that folder
  std::filesystem::path path;  ///< where it is: root / relative
  std::string relative;        ///< the client's path, as checked (e.g. "logs/a.plog")
};

/// a client path refused by ReadExistingFileInside: what() is "file '<path>': <rule>; expected
/// an existing file ending in <ext>, named relative to <folder>".
class InputPathError : public Error {
 public:
  InputPathError(const std::string& client_path, const std::string& rule,
                 std::string_view required_extension, std::string_view folder_name);
  /// the path as the client gave it (unescaped).
  const std::string& client_path() const { return client_path_; }
  /// the rule it broke, e.g. "is absolute (starts with '/')".
  const std::string& rule() const { return rule_; }

 private:
  std::string client_path_;
  std::string rule_;
};

/// a file read by ReadExistingFileInside.
struct ExistingInputFile {
  std::string text;            ///< its whole content
  std::filesystem::path path;  ///< where it is: root / relative
  std::string relative;        ///< the client's path, as checked (e.g. "presets/fog.yaml")
};

/// the walk below a trusted folder that every "inside this folder" rule uses (OpenNewFileInside,
/// ReadExistingFileInside, export's ReadRunFile): opens `parts[0]`, then `parts[1]` inside it,
/// ... up to but not including `parts.back()`, each relative to the one above with
/// openat(O_DIRECTORY | O_NOFOLLOW | O_CLOEXEC), so no symbolic link below `dir` is followed and
/// nothing can be swapped in between check and use.
/// @param dir    the open folder to start from (taken over)
/// @param refuse called with the folder that could not be opened from (fd), the index of the
///               part and errno when a step fails; must throw (the caller's error and message)
/// @returns the folder that holds `parts.back()`
/// @throws whatever `refuse` throws; Error if `refuse` returns.
UniqueFd OpenFoldersNoFollow(
    UniqueFd dir, const std::vector<std::string>& parts,
    const std::function<void(int parent_fd, size_t index, int err)>& refuse);

/// the longest client path accepted, in bytes.
inline constexpr size_t kMaxClientPathBytes = 1024;

/// checks `client_path` without touching the disk (the first four rules above) and returns
/// its components.
/// @throws OutputPathError naming the path and the rule it broke.
std::vector<std::string> CheckClientPath(std::string_view client_path,
                                         std::string_view required_extension);

/// creates the new file `client_path` inside the folder `root` under the rules above (file
/// mode 0644 less the umask).
/// @param root               the run's output folder (must exist)
/// @param client_path        the path a client sent, relative to `root`
/// @param required_extension the ending the name must have, with its dot (e.g. ".plog")
/// @throws OutputPathError naming `client_path` and the rule it broke (absolute, "..", empty
///         or "." component, control character, too long, wrong ending, a folder on the way
///         missing, not a folder or a symbolic link, the file existing, or the system's reason
///         the file could not be created); nothing is created then.
NewOutputFile OpenNewFileInside(const std::filesystem::path& root, std::string_view client_path,
                                std::string_view required_extension);

/// reads the existing regular file `client_path` inside the folder `root` under the read rules
/// above (the path rules of CheckClientPath; no symbolic link followed below `root`).
/// @param root               the folder the client may read from (taken as given: a link there
///                           is the user's own choice)
/// @param client_path        the path a client sent, relative to `root`
/// @param required_extension the ending the name must have, with its dot (e.g. ".yaml")
/// @param max_bytes          the largest file read; a larger one is refused before reading
/// @param folder_name        how errors name `root` to the client (e.g. "the world file's
///                           folder"); its absolute path is never named
/// @throws InputPathError naming `client_path` and the rule it broke (the rules of
///         CheckClientPath, a folder on the way or the file missing, a symbolic link, not a
///         folder, not a regular file, larger than `max_bytes`, or the system's reason it could
///         not be opened or read). the message never holds any of the file's content.
ExistingInputFile ReadExistingFileInside(const std::filesystem::path& root,
                                         std::string_view client_path,
                                         std::string_view required_extension, size_t max_bytes,
                                         std::string_view folder_name);

}  // namespace penumbra
