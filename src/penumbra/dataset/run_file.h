#pragma once
// reading the files of a run folder for export (dataset/run_folder.h, ros/rosbag_export.h)
// without following a symbolic link out of it. a run folder may come from someone else (a
// shared or downloaded run); a link inside it (rgb/000003.png -> /etc/shadow) would otherwise
// put any file the user can read into the exported dataset. the run folder itself may be
// reached through links (the user named it); below it every folder is opened with
// O_NOFOLLOW | O_DIRECTORY relative to its parent (openat) and every file with O_NOFOLLOW, so a
// link anywhere below the run folder is refused, with no window between a check and the open.

#include <cstdint>
#include <filesystem>
#include <limits>
#include <string>

namespace penumbra {

/// true if `relative` is a path inside a folder: not empty, not absolute, every component a
/// name (no "", "." or ".." component).
bool IsPlainRelativePath(const std::filesystem::path& relative);

/// what `relative` names under a run folder.
enum class RunEntry {
  kMissing,  ///< nothing there
  kFile,     ///< a regular file
  kFolder,   ///< a folder
  kOther,    ///< a FIFO, socket or device
};

/// what `relative` names under `run_dir`, reached through real folders only.
/// @throws ConfigError naming run_dir / relative if `relative` is not a plain relative path,
///         or if it or a folder on the way is a symbolic link.
RunEntry StatRunEntry(const std::filesystem::path& run_dir, const std::filesystem::path& relative);

/// the bytes of the regular file `relative` under `run_dir` (see the top of this file).
/// @throws ConfigError naming run_dir / relative if it is missing, is or lies below a
///         symbolic link, is not a regular file (a FIFO or device, which could block or never
///         end), is larger than `max_bytes`, or cannot be read.
std::string ReadRunFile(const std::filesystem::path& run_dir, const std::filesystem::path& relative,
                        uint64_t max_bytes = std::numeric_limits<uint64_t>::max());

}  // namespace penumbra
