#pragma once
// an effect's parameters given as JSON (a live change, live/live_effects.h) read through the
// effect types' own readers (effects/effect_type.h EffectParamReader): the keys and value
// types of the world file's `effects:` entries (docs/effects.md), with errors naming the key
// path and what was expected.

#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>
#include <vector>

#include "penumbra/effects/effect_type.h"

namespace penumbra {

/// a JSON object as an EffectParamReader. numbers are JSON numbers, vectors lists of 3 numbers,
/// booleans JSON booleans, enums and paths strings. relative paths resolve against the current
/// folder.
class JsonEffectReader : public EffectParamReader {
 public:
  /// `node` must outlive the reader; `path` prefixes the keys in errors ("effects.fog1").
  JsonEffectReader(const nlohmann::json& node, std::string path);

  bool Has(std::string_view k) const override;
  /// @throws ConfigError("", 0, "<path>.<k>", "expected a number" / ...) for a missing key or
  ///         a value of the wrong type.
  double Double(std::string_view k) const override;
  int Integer(std::string_view k) const override;
  Eigen::Vector3d Vector3(std::string_view k) const override;
  std::string String(std::string_view k) const override;
  bool Boolean(std::string_view k) const override;
  std::string Enum(std::string_view k, const std::vector<std::string_view>& valid) const override;
  std::vector<std::unique_ptr<EffectParamReader>> List(std::string_view k) const override;
  void ExpectKeys(const std::vector<std::string_view>& keys) const override;
  std::string ResolvePath(const std::string& path) const override;

 private:
  const nlohmann::json& Child(std::string_view k) const;
  [[noreturn]] void Fail(std::string_view k, const std::string& problem) const;

  const nlohmann::json& node_;
  std::string path_;
};

}  // namespace penumbra
