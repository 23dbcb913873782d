#include "penumbra/command/request_reader.h"

#include <fmt/format.h>

#include <cmath>

namespace penumbra {

std::string JsonTypeName(const nlohmann::json& v) {
  switch (v.type()) {
    case nlohmann::json::value_t::null:
      return "nil";
    case nlohmann::json::value_t::boolean:
      return "bool";
    case nlohmann::json::value_t::number_integer:
    case nlohmann::json::value_t::number_unsigned:
      return "integer";
    case nlohmann::json::value_t::number_float:
      return "float";
    case nlohmann::json::value_t::string:
      return "string";
    case nlohmann::json::value_t::array:
      return "array";
    case nlohmann::json::value_t::object:
      return "map";
    case nlohmann::json::value_t::binary:
      return "bin";
    default:
      return "unknown";
  }
}

RequestReader::RequestReader(const nlohmann::json& request) : request_(request) {
  read_.insert("cmd");
  read_.insert("id");
}

bool RequestReader::Has(const std::string& field) const {
  auto it = request_.find(field);
  return it != request_.end() && !it->is_null();
}

const nlohmann::json* RequestReader::Find(const std::string& field, bool required) {
  read_.insert(field);
  auto it = request_.find(field);
  if (it == request_.end() || it->is_null()) {
    if (required)
      throw CommandError(command_code::kMissingField, field,
                         fmt::format("missing field '{}'", field));
    return nullptr;
  }
  return &*it;
}

bool RequestReader::Present(const std::string& field) {
  read_.insert(field);
  return request_.contains(field);
}

const nlohmann::json& RequestReader::Raw(const std::string& field) { return *Find(field, true); }

int64_t RequestReader::Int(const std::string& field, int64_t lo, int64_t hi,
                           std::optional<int64_t> fallback) {
  const nlohmann::json* v = Find(field, !fallback.has_value());
  if (!v) return *fallback;
  int64_t x = 0;
  if (v->is_number_integer()) {
    x = v->get<int64_t>();
  } else if (v->is_number_unsigned()) {
    const uint64_t u = v->get<uint64_t>();
    x = u > static_cast<uint64_t>(INT64_MAX) ? INT64_MAX : static_cast<int64_t>(u);
  } else {
    throw CommandError(command_code::kBadField, field,
                       fmt::format("'{}' is a {}; expected an integer in [{}, {}]", field,
                                   JsonTypeName(*v), lo, hi));
  }
  if (x < lo || x > hi)
    throw CommandError(
        command_code::kBadField, field,
        fmt::format("'{}' is {}; expected an integer in [{}, {}]", field, x, lo, hi));
  return x;
}

double RequestReader::RealValue(const nlohmann::json& v, const std::string& field) {
  if (!v.is_number())
    throw CommandError(command_code::kBadField, field,
                       fmt::format("'{}' is a {}; expected a number", field, JsonTypeName(v)));
  const double x = v.get<double>();
  if (!std::isfinite(x))
    throw CommandError(command_code::kBadField, field,
                       fmt::format("'{}' is {}; expected a finite number", field, x));
  return x;
}

double RequestReader::Real(const std::string& field, double lo, double hi,
                           std::optional<double> fallback) {
  const nlohmann::json* v = Find(field, !fallback.has_value());
  if (!v) return *fallback;
  const double x = RealValue(*v, field);
  if (x < lo || x > hi)
    throw CommandError(command_code::kBadField, field,
                       fmt::format("'{}' is {}; expected a number in [{}, {}]", field, x, lo, hi));
  return x;
}

bool RequestReader::Bool(const std::string& field, std::optional<bool> fallback) {
  const nlohmann::json* v = Find(field, !fallback.has_value());
  if (!v) return *fallback;
  if (!v->is_boolean())
    throw CommandError(command_code::kBadField, field,
                       fmt::format("'{}' is a {}; expected a bool", field, JsonTypeName(*v)));
  return v->get<bool>();
}

std::string RequestReader::String(const std::string& field, std::optional<std::string> fallback) {
  const nlohmann::json* v = Find(field, !fallback.has_value());
  if (!v) return *fallback;
  if (!v->is_string())
    throw CommandError(command_code::kBadField, field,
                       fmt::format("'{}' is a {}; expected a string", field, JsonTypeName(*v)));
  return v->get<std::string>();
}

std::vector<double> RequestReader::Reals(const std::string& field, int size, int min_size) {
  const nlohmann::json& v = *Find(field, true);
  if (!v.is_array())
    throw CommandError(
        command_code::kBadField, field,
        fmt::format("'{}' is a {}; expected an array of numbers", field, JsonTypeName(v)));
  if (size >= 0 && static_cast<int>(v.size()) != size)
    throw CommandError(command_code::kBadField, field,
                       fmt::format("'{}' has {} values; expected {}", field, v.size(), size));
  if (size < 0 && static_cast<int>(v.size()) < min_size)
    throw CommandError(
        command_code::kBadField, field,
        fmt::format("'{}' has {} values; expected at least {}", field, v.size(), min_size));
  std::vector<double> out;
  out.reserve(v.size());
  for (size_t i = 0; i < v.size(); ++i)
    out.push_back(RealValue(v[i], fmt::format("{}[{}]", field, i)));
  return out;
}

void RequestReader::CheckNoUnknown() const {
  for (auto it = request_.begin(); it != request_.end(); ++it)
    if (!read_.count(it.key()))
      throw CommandError(command_code::kUnknownField, it.key(),
                         fmt::format("unknown field '{}' for command '{}'", it.key(),
                                     request_.value("cmd", std::string("?"))));
}

}  // namespace penumbra
