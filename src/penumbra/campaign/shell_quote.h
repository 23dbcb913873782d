#pragma once
// quoting for the shell scripts the benchmark writes for people and for Slurm (a method's
// command.sh, the sbatch array script): every value goes through ShellQuote, which makes any
// string one literal word of /bin/sh and bash. nothing the benchmark runs itself goes through
// a shell (campaign/command_template.h).

#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace penumbra {

/// `s` as one literal word of a POSIX shell: wrapped in single quotes, each ' written as '\''
/// ("" gives ''). every byte but NUL survives unchanged (newlines, $, `, \, ", non-UTF-8).
/// @throws Error when `s` holds a NUL byte (no shell word can carry one).
std::string ShellQuote(std::string_view s);

/// `argv` as one shell command line: words of only A-Z a-z 0-9 and _ - . / , : + = @ % are
/// written as they are (the first word quoted when it holds '=', which the shell would take
/// for an assignment), every other word through ShellQuote.
/// @throws Error as ShellQuote.
std::string ShellCommandLine(const std::vector<std::string>& argv);

/// the byte offset of the first control character in `s` (bytes 0x00-0x1f and 0x7f:
/// NUL, tab, newline, carriage return, escape, ...), or nullopt when it holds none.
std::optional<size_t> FindControlCharacter(std::string_view s);

}  // namespace penumbra
