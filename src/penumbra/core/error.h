#pragma once
// error types thrown across penumbra. every error names where it came from
// (file, key path or line) and what was expected, so users can fix their input.

#include <sstream>
#include <stdexcept>
#include <string>

namespace penumbra {

/// base class of every error penumbra throws on purpose.
class Error : public std::runtime_error {
 public:
  explicit Error(const std::string& what) : std::runtime_error(what) {}
};

/// bad user input: a world file, model file or command-line value.
/// the message has the form "<file>:<line>: <key.path>: <problem>; expected <...>".
class ConfigError : public Error {
 public:
  /// @param file   file that holds the bad value ("" when it came from the command line)
  /// @param line   1-based line in `file`, or 0 when unknown
  /// @param key    dotted key path, e.g. "cameras[0].rate_hz"
  /// @param problem what is wrong and what was expected
  ConfigError(const std::string& file, int line, const std::string& key,
              const std::string& problem)
      : Error(Format(file, line, key, problem)), file_(file), line_(line), key_(key) {}

  const std::string& file() const { return file_; }
  int line() const { return line_; }
  const std::string& key() const { return key_; }

 private:
  static std::string Format(const std::string& file, int line, const std::string& key,
                            const std::string& problem) {
    std::ostringstream s;
    s << (file.empty() ? "<command line>" : file);
    if (line > 0) s << ':' << line;
    if (!key.empty()) s << ": " << key;
    s << ": " << problem;
    return s.str();
  }
  std::string file_;
  int line_ = 0;
  std::string key_;
};

/// the physics engine reported an error or the simulation diverged.
class PhysicsError : public Error {
 public:
  explicit PhysicsError(const std::string& what) : Error(what) {}
};

}  // namespace penumbra
