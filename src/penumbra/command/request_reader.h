#pragma once
// typed, checked access to the fields of one command request (a JSON object decoded from the
// wire). every getter names the field in its CommandError; CheckNoUnknown() rejects keys no
// getter read, so a misspelt optional field is an error rather than silently ignored.

#include <cstdint>
#include <nlohmann/json.hpp>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "penumbra/command/command_error.h"

namespace penumbra {

/// reads the fields of `request` (which must outlive the reader). "cmd" and "id" count as read.
class RequestReader {
 public:
  explicit RequestReader(const nlohmann::json& request);

  /// true when `field` is present (and not null).
  bool Has(const std::string& field) const;

  /// the field as an integer in [lo, hi]; `fallback` when absent (nullopt = required).
  /// @throws CommandError missing_field / bad_field (not an integer, out of range).
  int64_t Int(const std::string& field, int64_t lo, int64_t hi,
              std::optional<int64_t> fallback = std::nullopt);
  /// a finite real (ints accepted) in [lo, hi]. @throws as Int.
  double Real(const std::string& field, double lo, double hi,
              std::optional<double> fallback = std::nullopt);
  bool Bool(const std::string& field, std::optional<bool> fallback = std::nullopt);
  std::string String(const std::string& field, std::optional<std::string> fallback = std::nullopt);
  /// a list of finite reals; `size` >= 0 requires that length, -1 any length >= `min_size`.
  std::vector<double> Reals(const std::string& field, int size, int min_size = 0);
  /// the raw value (marked read); @throws missing_field when absent.
  const nlohmann::json& Raw(const std::string& field);
  /// whether the request has `field`, null included (Has: not null); marks it read.
  bool Present(const std::string& field);

  /// @throws CommandError unknown_field naming the first key no getter read.
  void CheckNoUnknown() const;

  /// the whole request as decoded.
  const nlohmann::json& request() const { return request_; }

  /// `v` as a finite real, or throws bad_field naming `field`.
  static double RealValue(const nlohmann::json& v, const std::string& field);

 private:
  const nlohmann::json* Find(const std::string& field, bool required);

  const nlohmann::json& request_;
  std::set<std::string> read_;
};

/// the JSON type name of `v` for messages ("string", "integer", "float", "map", ...).
std::string JsonTypeName(const nlohmann::json& v);

}  // namespace penumbra
