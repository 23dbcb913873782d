#pragma once
// small text rules shared by the world file, the command line and the file readers: shell-style
// name patterns, and the strict decimal numbers Penumbra accepts wherever a person types one.

#include <optional>
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

}  // namespace penumbra
