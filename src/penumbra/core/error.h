#pragma once
// error types thrown across penumbra. every error names where it came from
// (file, key path or line) and what was expected, so users can fix their input.

#include <cstddef>
#include <stdexcept>
#include <string>
#include <string_view>

namespace penumbra {

/// base class of every error penumbra throws on purpose.
class Error : public std::runtime_error {
 public:
  explicit Error(const std::string& what) : std::runtime_error(what) {}
};

/// `text` made safe to print in one line of an error message: bytes that are not printable
/// ASCII or part of a valid UTF-8 sequence (control characters, binary garbage) are written as
/// `\xNN`, and a result longer than `max_bytes` keeps its first and last parts around
/// "... [N bytes elided] ...", so a 10 MB value cannot flood a terminal or a log.
std::string SanitizeForMessage(std::string_view text, size_t max_bytes = 512);

/// bad user input: a world file, model file or command-line value.
/// the message has the form "<file>:<line>: <key.path>: <problem>; expected <...>", with
/// file, key and problem passed through SanitizeForMessage (values quoted from the input
/// are echoed at most ~1 KiB long, non-printable bytes escaped).
class ConfigError : public Error {
 public:
  /// @param file   file that holds the bad value ("" when it came from the command line)
  /// @param line   1-based line in `file`, or 0 when unknown
  /// @param key    dotted key path, e.g. "cameras[0].rate_hz"
  /// @param problem what is wrong and what was expected
  ConfigError(const std::string& file, int line, const std::string& key, const std::string& problem)
      : Error(Format(file, line, key, problem)),
        file_(file),
        line_(line),
        key_(key),
        problem_(problem) {}

  const std::string& file() const { return file_; }
  int line() const { return line_; }
  const std::string& key() const { return key_; }
  /// the problem as given (not sanitized; what() holds the printable form).
  const std::string& problem() const { return problem_; }

 private:
  static std::string Format(const std::string& file, int line, const std::string& key,
                            const std::string& problem);
  std::string file_;
  int line_ = 0;
  std::string key_;
  std::string problem_;
};

/// the physics engine reported an error or the simulation diverged.
class PhysicsError : public Error {
 public:
  explicit PhysicsError(const std::string& what) : Error(what) {}
};

}  // namespace penumbra
