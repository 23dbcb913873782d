#pragma once
// the strict option types and shared argument readers of the `penumbra` verbs (app/command.h):
// plain decimal numbers only (CLI11's own conversion accepts hex 0x10, octal and binary
// prefixes and nan/inf, and clamps out-of-range integers), and a world file or a bare model.

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <string_view>

#include "penumbra/world/world_config.h"

namespace CLI {
class App;
class Option;
}  // namespace CLI

namespace penumbra {

/// an unsigned decimal integer: digits only (a leading '+' is allowed); nullopt otherwise or
/// when it does not fit uint64.
std::optional<uint64_t> ParseUnsigned(std::string_view s);

/// a decimal integer that fits int64: [+-]digits; nullopt otherwise.
std::optional<int64_t> ParseInteger(std::string_view s);

/// an integer option `name` in [lo, hi] (type name INT) written to `*target`.
CLI::Option* AddInteger(CLI::App* app, const std::string& name, int* target, int64_t lo, int64_t hi,
                        const std::string& help);

/// any uint64 (seeds): 0 .. 18446744073709551615, recorded exactly (type name UINT64).
CLI::Option* AddUint64(CLI::App* app, const std::string& name, std::optional<uint64_t>* target,
                       const std::string& help);

/// a finite decimal number option: > lo (lo_open) or >= lo (type name NUM), handed to `set`.
CLI::Option* AddDecimal(CLI::App* app, const std::string& name, std::function<void(double)> set,
                        double lo, bool lo_open, const std::string& help);

/// a world file (.yaml, .yml) or a bare model (.xml MJCF, .mjcf, .urdf) as a world.
/// @throws ConfigError naming the file for another extension, and what the readers throw.
WorldConfig LoadWorldOrModel(const std::string& path);

}  // namespace penumbra
