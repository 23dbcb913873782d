#include "penumbra/app/cli_options.h"

#include <fmt/format.h>

#include <CLI/CLI.hpp>
#include <charconv>
#include <filesystem>

#include "penumbra/core/error.h"
#include "penumbra/core/text_match.h"

namespace penumbra {

std::optional<uint64_t> ParseUnsigned(std::string_view s) {
  if (!s.empty() && s.front() == '+') s.remove_prefix(1);
  if (s.empty()) return std::nullopt;
  for (char c : s)
    if (c < '0' || c > '9') return std::nullopt;
  uint64_t v = 0;
  const auto r = std::from_chars(s.data(), s.data() + s.size(), v);
  if (r.ec != std::errc() || r.ptr != s.data() + s.size()) return std::nullopt;
  return v;
}

std::optional<int64_t> ParseInteger(std::string_view s) {
  std::string_view digits = s;
  if (!digits.empty() && (digits.front() == '+' || digits.front() == '-')) digits.remove_prefix(1);
  if (!ParseUnsigned(digits) || digits.front() == '+') return std::nullopt;
  if (s.front() == '+') s.remove_prefix(1);
  int64_t v = 0;
  const auto r = std::from_chars(s.data(), s.data() + s.size(), v);
  if (r.ec != std::errc() || r.ptr != s.data() + s.size()) return std::nullopt;
  return v;
}

CLI::Option* AddInteger(CLI::App* app, const std::string& name, int* target, int64_t lo, int64_t hi,
                        const std::string& help) {
  const std::string range = fmt::format("an integer in [{}, {}]", lo, hi);
  return app
      ->add_option_function<std::string>(
          name, [target](const std::string& s) { *target = static_cast<int>(*ParseInteger(s)); },
          help)
      ->type_name("INT")
      ->check(CLI::Validator(
          [lo, hi, range](std::string& s) -> std::string {
            const std::optional<int64_t> v = ParseInteger(s);
            if (!v || *v < lo || *v > hi) return "'" + s + "' is not " + range;
            return "";
          },
          range, ""));
}

CLI::Option* AddUint64(CLI::App* app, const std::string& name, std::optional<uint64_t>* target,
                       const std::string& help) {
  return app
      ->add_option_function<std::string>(
          name, [target](const std::string& s) { *target = *ParseUnsigned(s); }, help)
      ->type_name("UINT64")
      ->check(CLI::Validator(
          [](std::string& s) -> std::string {
            if (!s.empty() && s.front() == '-')
              return "'" + s + "' is negative; expected an integer in [0, 2^64 - 1]";
            if (!ParseUnsigned(s))
              return "'" + s + "' is not a decimal integer in [0, 2^64 - 1] (18446744073709551615)";
            return "";
          },
          "UINT64", ""));
}

CLI::Option* AddDecimal(CLI::App* app, const std::string& name, std::function<void(double)> set,
                        double lo, bool lo_open, const std::string& help) {
  const std::string range = fmt::format("a finite decimal number {} {}", lo_open ? ">" : ">=", lo);
  return app
      ->add_option_function<std::string>(
          name, [set](const std::string& s) { set(*ParseDecimal(s)); }, help)
      ->type_name("NUM")
      ->check(CLI::Validator(
          [lo, lo_open, range](std::string& s) -> std::string {
            const std::optional<double> v = ParseDecimal(s);
            if (!v) return "'" + s + "' is not " + range;
            if (lo_open ? !(*v > lo) : !(*v >= lo))
              return "'" + s + "' is out of range; expected " + range;
            return "";
          },
          range, ""));
}

WorldConfig LoadWorldOrModel(const std::string& path) {
  const std::string ext = std::filesystem::path(path).extension().string();
  if (ext == ".xml" || ext == ".urdf" || ext == ".mjcf") return WorldForBareModel(path);
  if (ext == ".yaml" || ext == ".yml") return LoadWorldFile(path);
  throw ConfigError(path, 0, "",
                    "unknown file type '" + ext +
                        "'; expected a world file (.yaml, .yml) or a model (.xml MJCF, .urdf)");
}

}  // namespace penumbra
