#pragma once
// the one way Penumbra opens and reads its input files (world files, presets, specs, run logs,
// trajectories, policies' side files, ...), beside output_file.h. an input file is a regular
// file and nothing else: it is opened with O_NONBLOCK, so that a FIFO opens at once instead of
// waiting for a writer for ever, checked with fstat on the open descriptor (no window between
// a check and the use), and refused naming the path and what it is (a directory, a FIFO, a
// character or block device, a socket); O_NONBLOCK is cleared again before it is returned.
// ReadInputFile reads such a file whole, its size checked against a cap before anything is
// allocated.

#include <sys/types.h>

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>

#include "penumbra/core/output_path_policy.h"

namespace penumbra {

/// the default cap of ReadInputFile: 256 MiB (far above any world, preset or spec file).
inline constexpr size_t kMaxInputFileBytes = size_t{256} << 20;

/// whether OpenInputFile follows a symbolic link that the path itself names (links in the
/// folders on the way are always followed: the caller confines those where it must).
enum class InputLinks {
  kFollow,  ///< the user named the path: a link to a regular file is fine
  kRefuse,  ///< the path came from a file or a client: opened with O_NOFOLLOW
};

/// a regular file opened by OpenInputFile.
struct InputFile {
  UniqueFd fd;        ///< open O_RDONLY | O_CLOEXEC (blocking), at offset 0
  uint64_t size = 0;  ///< its size when it was opened (fstat), bytes
};

/// what a file of mode `st_mode` is, for messages: "a regular file", "a directory", "a FIFO",
/// "a character device", "a block device", "a socket", "a symbolic link" or "an unknown kind of
/// file".
std::string FileKindName(mode_t st_mode);

/// opens `path` as a regular file for reading, without ever blocking in open() (see the top
/// of this file). `what` names the file in messages ("run log", "TUM trajectory"; default
/// "file").
/// @throws ConfigError(path, 0, "", problem) with problem "<what> not found: <absolute path>;
///         expected an existing file", "<what> is a directory; expected a regular file",
///         "<what> is not a regular file (a FIFO); expected a regular file" (likewise a
///         character device, block device, socket), "<what> is a symbolic link; expected a
///         regular file (links are not followed here)" (links = kRefuse) or "cannot read the
///         <what>: <reason>; expected a readable file".
InputFile OpenInputFile(const std::filesystem::path& path, const std::string& what = "file",
                        InputLinks links = InputLinks::kFollow);

/// the whole of the regular file `path` (opened by OpenInputFile, so followed if a link unless
/// `links` is kRefuse), as bytes. `what` names the file in messages ("world file", "adversity
/// preset file"; default "file").
/// the size is read with fstat on the open file and checked against `max_bytes` before the
/// buffer is allocated; a file that grows while it is read is cut at `max_bytes` + 1 bytes and
/// refused as too large.
/// @throws ConfigError(path, 0, "", problem): every problem of OpenInputFile, and "<what> is N
///         bytes; expected at most M bytes" or "cannot read the <what>: <reason>; expected a
///         readable file".
std::string ReadInputFile(const std::filesystem::path& path, const std::string& what = "file",
                          size_t max_bytes = kMaxInputFileBytes,
                          InputLinks links = InputLinks::kFollow);

}  // namespace penumbra
