#pragma once
// small text rules shared by the world file, the command line and the file readers: shell-style
// name patterns, and the strict decimal numbers Penumbra accepts wherever a person types one.

#include <cstddef>
#include <optional>
#include <string>
#include <string_view>

namespace penumbra {

/// true when `text` matches the shell-style `pattern` as a whole: '*' matches any run of
/// characters (also none, also '/'), '?' exactly one character; every other character matches
/// itself (case-sensitive). e.g. GlobMatch("go1/*_foot", "go1/FR_foot").
bool GlobMatch(std::string_view pattern, std::string_view text);

/// a finite decimal number: [+-]digits[.digits][(e|E)[+-]digits] with at least one digit
/// before the exponent ("1", "-0.5", ".5", "2.", "1e-3"); nullopt for anything else: hex
/// ("0x10"), "inf", "nan", a value that overflows a double, "+-1", surrounding spaces.
std::optional<double> ParseDecimal(std::string_view s);

/// longest name (bytes) of an object that a world file names: robots, models, lights, cameras,
/// sensors, sites, effects, agents, metric series, semantic classes and adversity presets.
/// names become folder and file names (at most 255 bytes each) and appear in every message
/// about the object (docs/world-file.md "Input limits").
inline constexpr size_t kMaxNameLength = 64;

/// what is wrong with the length of `name`, or nothing when it has at most kMaxNameLength
/// bytes: "a name of 100000 characters ('aaaaaaaaaaaaaaaa...'); expected at most 64 characters".
/// only the first 16 bytes are echoed (control characters escaped).
std::optional<std::string> NameLengthProblem(std::string_view name);

/// the first `max_bytes` of `text` (printable: control characters and bytes that are not UTF-8
/// escaped as \xNN), followed by "..." when anything was cut; for echoing user input.
std::string Excerpt(std::string_view text, size_t max_bytes = 32);

}  // namespace penumbra
