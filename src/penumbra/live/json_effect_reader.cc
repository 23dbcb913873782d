#include "penumbra/live/json_effect_reader.h"

#include <climits>
#include <cmath>
#include <filesystem>

#include "penumbra/core/error.h"

namespace penumbra {

JsonEffectReader::JsonEffectReader(const nlohmann::json& node, std::string path)
    : node_(node), path_(std::move(path)) {}

void JsonEffectReader::Fail(std::string_view k, const std::string& problem) const {
  throw ConfigError("", 0, path_.empty() ? std::string(k) : path_ + "." + std::string(k), problem);
}

bool JsonEffectReader::Has(std::string_view k) const {
  return node_.is_object() && node_.contains(std::string(k));
}

const nlohmann::json& JsonEffectReader::Child(std::string_view k) const {
  if (!Has(k)) Fail(k, "missing; expected a value");
  return node_.at(std::string(k));
}

double JsonEffectReader::Double(std::string_view k) const {
  const nlohmann::json& v = Child(k);
  if (!v.is_number() || !std::isfinite(v.get<double>()))
    Fail(k, "got " + v.dump() + "; expected a number");
  return v.get<double>();
}

int JsonEffectReader::Integer(std::string_view k) const {
  const nlohmann::json& v = Child(k);
  if (v.is_number_integer() && v.get<int64_t>() >= INT_MIN && v.get<int64_t>() <= INT_MAX)
    return static_cast<int>(v.get<int64_t>());
  Fail(k, "got " + v.dump() + "; expected an integer");
}

Eigen::Vector3d JsonEffectReader::Vector3(std::string_view k) const {
  const nlohmann::json& v = Child(k);
  if (!v.is_array() || v.size() != 3) Fail(k, "got " + v.dump() + "; expected a list of 3 numbers");
  Eigen::Vector3d out;
  for (int i = 0; i < 3; ++i) {
    if (!v[i].is_number() || !std::isfinite(v[i].get<double>()))
      Fail(k, "got " + v.dump() + "; expected a list of 3 numbers");
    out[i] = v[i].get<double>();
  }
  return out;
}

std::string JsonEffectReader::String(std::string_view k) const {
  const nlohmann::json& v = Child(k);
  if (!v.is_string()) Fail(k, "got " + v.dump() + "; expected a string");
  return v.get<std::string>();
}

bool JsonEffectReader::Boolean(std::string_view k) const {
  const nlohmann::json& v = Child(k);
  if (!v.is_boolean()) Fail(k, "got " + v.dump() + "; expected true or false");
  return v.get<bool>();
}

std::string JsonEffectReader::Enum(std::string_view k,
                                   const std::vector<std::string_view>& valid) const {
  const std::string s = String(k);
  std::string list;
  for (std::string_view v : valid) {
    if (v == s) return s;
    list += (list.empty() ? "" : ", ") + std::string(v);
  }
  Fail(k, "unknown value '" + s + "'; expected one of: " + list);
}

std::vector<std::unique_ptr<EffectParamReader>> JsonEffectReader::List(std::string_view k) const {
  const nlohmann::json& v = Child(k);
  if (!v.is_array()) Fail(k, "got " + v.dump() + "; expected a list");
  std::vector<std::unique_ptr<EffectParamReader>> out;
  const std::string base = path_.empty() ? std::string(k) : path_ + "." + std::string(k);
  for (size_t i = 0; i < v.size(); ++i)
    out.push_back(std::make_unique<JsonEffectReader>(v[i], base + "[" + std::to_string(i) + "]"));
  return out;
}

void JsonEffectReader::ExpectKeys(const std::vector<std::string_view>& keys) const {
  if (!node_.is_object())
    throw ConfigError("", 0, path_, "got " + node_.dump() + "; expected an object");
  for (const auto& [key, value] : node_.items()) {
    bool known = false;
    std::string list;
    for (std::string_view v : keys) {
      known = known || v == key;
      list += (list.empty() ? "" : ", ") + std::string(v);
    }
    if (!known) Fail(key, "unknown key '" + key + "'; expected one of: " + list);
  }
}

std::string JsonEffectReader::ResolvePath(const std::string& path) const {
  std::filesystem::path p(path);
  if (p.is_relative()) p = std::filesystem::current_path() / p;
  return p.lexically_normal().string();
}

}  // namespace penumbra
