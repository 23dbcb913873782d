#pragma once
// the one whole-file read of Penumbra's inputs (world files, presets, specs, policies' side
// files, ...), beside output_file.h: the file's size is checked against a cap before anything
// is allocated, and every failure names the file and the reason.

#include <cstddef>
#include <filesystem>
#include <string>

namespace penumbra {

/// the default cap of ReadInputFile: 256 MiB (far above any world, preset or spec file).
inline constexpr size_t kMaxInputFileBytes = size_t{256} << 20;

/// the whole of the regular file `path` (followed if a link), as bytes. `what` names the file
/// in messages ("world file", "adversity preset file"; default "file").
/// the size is read with fstat on the open file and checked against `max_bytes` before the
/// buffer is allocated; a file that grows while it is read is cut at `max_bytes` + 1 bytes and
/// refused as too large.
/// @throws ConfigError(path, 0, "", problem) with problem "<what> not found: <absolute path>;
///         expected an existing file", "<what> is not a regular file; expected a file",
///         "<what> is N bytes; expected at most M bytes" or "cannot read the <what>: <reason>;
///         expected a readable file".
std::string ReadInputFile(const std::filesystem::path& path, const std::string& what = "file",
                          size_t max_bytes = kMaxInputFileBytes);

}  // namespace penumbra
