#pragma once
// small text helpers of the scene composer: MJCF number lists and file paths.
// internal to src/penumbra/compose.

#include <optional>
#include <string>
#include <vector>

namespace penumbra::compose {

/// parses a whitespace-separated list of real numbers; nullopt if any token is not a
/// number (strtod syntax, as MuJoCo's reader).
std::optional<std::vector<double>> ParseNumbers(const std::string& text);

/// formats numbers with the shortest text that reads back bit-identically, space separated.
std::string FormatNumbers(const std::vector<double>& values);

/// true if `path` is absolute (starts with '/').
bool IsAbsolutePath(const std::string& path);

/// folder part of `path` with a trailing '/', or "" if it has none.
std::string DirName(const std::string& path);

/// joins a folder and a relative path ("a" + "b/c" -> "a/b/c").
std::string JoinPath(const std::string& dir, const std::string& rel);

/// makes `path` absolute (against the current directory) and removes "." and ".." parts.
std::string NormalizePath(const std::string& path);

/// file name without folders (MuJoCo strippath).
std::string StripPath(const std::string& path);

/// true if a regular file exists at `path`.
bool FileExists(const std::string& path);

/// lowercase copy.
std::string ToLower(std::string s);

}  // namespace penumbra::compose
