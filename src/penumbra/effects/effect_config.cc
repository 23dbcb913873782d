#include "penumbra/effects/effect_config.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <concepts>
#include <map>
#include <utility>

#include "penumbra/core/error.h"
#include "penumbra/core/text_match.h"
#include "penumbra/scene/scene_limits.h"

namespace penumbra {

bool EffectRange::Contains(double v) const {
  if (std::isnan(v)) return false;
  if (std::isinf(v) && !(v == hi && !hi_open)) return false;
  return (lo_open ? v > lo : v >= lo) && (hi_open ? v < hi : v <= hi);
}

std::string EffectRange::ToString() const {
  using N = EffectChecker;
  if (lo == -kInf && hi == kInf) return "a finite number";
  if (hi == kInf) return (lo_open ? "> " : ">= ") + N::Num(lo);
  return std::string(lo_open ? "(" : "[") + N::Num(lo) + ", " + N::Num(hi) + (hi_open ? ")" : "]");
}

std::string EffectChecker::Num(double v) {
  char buf[64];
  auto r = std::to_chars(buf, buf + sizeof(buf), v);
  return std::string(buf, r.ptr);
}

std::string EffectChecker::Vec(const Eigen::Vector3d& v) {
  std::string s = "[";
  s += Num(v[0]);
  s += ", ";
  s += Num(v[1]);
  s += ", ";
  s += Num(v[2]);
  s += "]";
  return s;
}

void EffectChecker::Fail(const std::string& key, const std::string& message) {
  if (!problem_) problem_ = EffectProblem{key, message};
}

void EffectChecker::In(const std::string& key, double v, EffectRange r) {
  if (!r.Contains(v)) Fail(key, Num(v) + " is out of range; expected " + r.ToString());
}

void EffectChecker::In3(const std::string& key, const Eigen::Vector3d& v, EffectRange r) {
  for (int i = 0; i < 3; ++i) {
    if (!r.Contains(v[i])) {
      Fail(key, Vec(v) + " is out of range; expected 3 numbers, each " + r.ToString());
      return;
    }
  }
}

namespace {

// the hooks every effect type must have (effect_type.h); a type without them fails here with
// the name of the missing one rather than deep inside std::visit.
template <class P>
concept EffectTypeParams = requires(P p, const P& cp, const EffectParamReader& r,
                                    const EffectConfig& e, EffectChecker* c,
                                    const EffectBindContext& ctx) {
  { P::kTypeName } -> std::convertible_to<std::string_view>;
  { P::Keys() } -> std::same_as<std::vector<std::string_view>>;
  p.Read(r);
  cp.Validate(e, c);
  { cp.Bind(e, ctx) } -> std::same_as<std::unique_ptr<EffectInstance>>;
};

// the registry entry of alternative I of EffectParams, made from the type's hooks.
template <size_t I>
EffectTypeInfo MakeTypeInfo() {
  using P = std::variant_alternative_t<I, EffectParams>;
  static_assert(EffectTypeParams<P>, "an effect type lacks a hook of effects/effect_type.h");
  EffectTypeInfo info;
  info.name = std::string(P::kTypeName);
  info.index = I;
  info.keys = P::Keys();
  info.read = [](const EffectParamReader& r, EffectConfig* e) {
    P& p = e->params.template emplace<I>();
    p.Read(r);
  };
  return info;
}

template <size_t... I>
std::vector<EffectTypeInfo> MakeRegistry(std::index_sequence<I...>) {
  return {MakeTypeInfo<I>()...};
}

bool IsValidName(const std::string& name) {
  if (name.empty()) return false;
  return std::all_of(name.begin(), name.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-';
  });
}

}  // namespace

const std::vector<EffectTypeInfo>& EffectTypes() {
  static const std::vector<EffectTypeInfo> kTypes =
      MakeRegistry(std::make_index_sequence<std::variant_size_v<EffectParams>>());
  return kTypes;
}

const EffectTypeInfo* FindEffectType(std::string_view name) {
  for (const EffectTypeInfo& t : EffectTypes())
    if (t.name == name) return &t;
  return nullptr;
}

const std::vector<std::string>& EffectTypeNames() {
  static const std::vector<std::string> kNames = [] {
    std::vector<std::string> names;
    for (const EffectTypeInfo& t : EffectTypes()) names.push_back(t.name);
    return names;
  }();
  return kNames;
}

const EffectTypeInfo& EffectConfig::type() const { return EffectTypes()[params.index()]; }

const std::string& EffectConfig::type_name() const { return type().name; }

double EffectConfig::Weight(double t) const {
  if (!(t >= start_sec) || t > stop_sec) return 0;
  double w = 1;
  if (fade_in_sec > 0) w *= std::clamp((t - start_sec) / fade_in_sec, 0.0, 1.0);
  if (fade_out_sec > 0 && std::isfinite(stop_sec)) {
    w *= std::clamp((stop_sec - t) / fade_out_sec, 0.0, 1.0);
  }
  return w;
}

std::optional<EffectConfig::Problem> EffectConfig::Validate() const {
  using R = EffectRange;
  EffectChecker c;
  if (auto problem = NameLengthProblem(name)) {
    c.Fail("name", *problem);
  } else if (!IsValidName(name)) {
    c.Fail("name", "'" + name +
                       "' is not a valid effect name; expected a non-empty name of "
                       "the characters A-Z a-z 0-9 _ -");
  }
  c.In("start_sec", start_sec, R::Closed(0, kMaxDurationSec));
  // stop_sec is infinite unless given; given, it is a time of a run (at most kMaxDurationSec)
  if (c.ok() && std::isfinite(stop_sec)) c.In("stop_sec", stop_sec, R::Closed(0, kMaxDurationSec));
  if (c.ok() && !(stop_sec > start_sec)) {
    c.Fail("stop_sec", EffectChecker::Num(stop_sec) + " is out of range; expected > start_sec (" +
                           EffectChecker::Num(start_sec) + ")");
  }
  c.In("fade_in_sec", fade_in_sec, R::Closed(0, kMaxDurationSec));
  c.In("fade_out_sec", fade_out_sec, R::Closed(0, kMaxDurationSec));
  if (region) {
    c.In3("region.min", region->min_W, R::Closed(-kMaxPositionM, kMaxPositionM));
    c.In3("region.max", region->max_W, R::Closed(-kMaxPositionM, kMaxPositionM));
    if (c.ok() && (region->min_W.array() >= region->max_W.array()).any()) {
      c.Fail("region.min", "region min " + EffectChecker::Vec(region->min_W) +
                               " is not below max " + EffectChecker::Vec(region->max_W) +
                               "; expected min < max on every axis");
    }
  }
  if (!c.ok()) return c.problem();
  std::visit([&](const auto& p) { p.Validate(*this, &c); }, params);
  return c.problem();
}

std::optional<double> EffectFluidDtSec(const EffectConfig& e) {
  return std::visit(
      [](const auto& p) -> std::optional<double> {
        if constexpr (requires { p.FluidDtSec(); }) {
          return p.FluidDtSec();
        } else {
          return std::nullopt;
        }
      },
      e.params);
}

std::unique_ptr<EffectInstance> BindEffect(const EffectConfig& e, const EffectBindContext& ctx) {
  return std::visit([&](const auto& p) { return p.Bind(e, ctx); }, e.params);
}

namespace {

[[noreturn]] void ThrowProblem(const EffectConfig& e, const std::string& prefix,
                               const EffectConfig::Problem& p, const std::string& file,
                               const std::function<int(const std::string&)>& line_of) {
  const std::string key = prefix + "." + p.key;
  throw ConfigError(file, line_of ? line_of(key) : 0, key,
                    "effect '" + e.name + "' (" + e.type_name() + "): " + p.message);
}

}  // namespace

void EffectConfig::ValidateOrThrow(const std::string& key_prefix) const {
  if (auto p = Validate()) {
    ThrowProblem(*this, key_prefix.empty() ? "effects['" + name + "']" : key_prefix, *p, "", {});
  }
}

void ValidateEffectsOrThrow(const std::vector<EffectConfig>& effects, const std::string& file,
                            const std::function<int(const std::string&)>& line_of) {
  std::map<std::string, size_t> names;
  for (size_t i = 0; i < effects.size(); ++i) {
    const EffectConfig& e = effects[i];
    const std::string prefix = "effects[" + std::to_string(i) + "]";
    if (auto p = e.Validate()) ThrowProblem(e, prefix, *p, file, line_of);
    auto [it, inserted] = names.emplace(e.name, i);
    if (!inserted) {
      ThrowProblem(e, prefix,
                   {"name", "name '" + e.name + "' is also used by effects[" +
                                std::to_string(it->second) + "]; expected unique effect names"},
                   file, line_of);
    }
  }
  // references between effects (wetness -> rain, sparks -> fire)
  for (size_t i = 0; i < effects.size(); ++i) {
    const EffectConfig& e = effects[i];
    const std::optional<EffectProblem> p = std::visit(
        [&](const auto& params) -> std::optional<EffectProblem> {
          if constexpr (requires { params.CheckReferences(effects); }) {
            return params.CheckReferences(effects);
          } else {
            return std::nullopt;
          }
        },
        e.params);
    if (p) ThrowProblem(e, "effects[" + std::to_string(i) + "]", *p, file, line_of);
  }
}

}  // namespace penumbra
