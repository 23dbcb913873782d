#pragma once
// configuration of the adverse-condition effects: one EffectConfig per entry of the world
// file's `effects:` list (parsed by world/effects_reader.h, reference in docs/effects.md):
// the keys every effect has, and the parameters of its type (effects/types/<type>.h, listed
// in effect_types.h). every struct has defaults, documented units and valid ranges, and
// EffectConfig::ValidateOrThrow() checks them.
//
// frames and units: world frame W (REP-103/REP-105: x east, y north, z up; metres,
// seconds); colours linear Rec.709 rgb; `_deg`, `_hz`, `_sec`, `_mm_h` as named.
//
// time window: an effect is active for start_sec <= t <= stop_sec. its weight
//   w(t) = clamp((t - start_sec) / fade_in_sec, 0, 1) * clamp((stop_sec - t) / fade_out_sec, 0, 1)
// (a zero fade time is a hard switch) scales media extinction, precipitation rate (by
// deterministic thinning of particles), emission, and blends light multipliers towards 1.

#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "penumbra/effects/effect_type.h"
#include "penumbra/effects/effect_types.h"
#include "penumbra/scene/effects_frame.h"

namespace penumbra {

struct EffectTypeInfo;

/// one entry of the world file's `effects:` list.
struct EffectConfig {
  std::string name;  ///< unique among effects; [A-Za-z0-9_-]+
  /// the type and its parameters (effect_types.h); default: fog with default parameters.
  EffectParams params;
  double start_sec = 0;                                       ///< >= 0
  double stop_sec = std::numeric_limits<double>::infinity();  ///< > start_sec (inf = never)
  double fade_in_sec = 0;                                     ///< >= 0
  double fade_out_sec = 0;                                    ///< >= 0
  /// where the effect lives, world frame. fog/dust: the medium's box (nullopt = everywhere);
  /// smoke/fire: the simulation grid box (required); vdb_smoke: fit box (optional);
  /// rain/snow: drops only inside it (nullopt = everywhere); others: unused.
  std::optional<BoxRegion> region;

  /// whether the effect is of type P (FogParams, RainParams, ...).
  template <class P>
  bool Is() const {
    return std::holds_alternative<P>(params);
  }
  /// the parameters of type P. @throws std::bad_variant_access when the effect is another type.
  template <class P>
  P& Get() {
    return std::get<P>(params);
  }
  template <class P>
  const P& Get() const {
    return std::get<P>(params);
  }
  /// the parameters of type P, or null when the effect is another type.
  template <class P>
  const P* GetIf() const {
    return std::get_if<P>(&params);
  }
  /// the registry entry of the effect's type.
  const EffectTypeInfo& type() const;
  /// world-file name of the effect's type ("fog", "vdb_smoke", ...).
  const std::string& type_name() const;

  /// weight w(t) in [0, 1] of the time window and fades (see the file header).
  double Weight(double time_sec) const;

  /// a problem found by Validate() (keys relative to the entry; a type's parameters sit next
  /// to name and type).
  using Problem = EffectProblem;
  /// the first problem of this effect's values (the common keys, then the type's
  /// Validate), or nullopt. does not read .vdb files (only checks that they exist).
  std::optional<Problem> Validate() const;

  /// @param key_prefix prefix of key paths in the error ("effects[2]"); "" = "effects['<name>']".
  /// @throws ConfigError("", 0, "<prefix>.<key>", "effect '<name>' (<type>): <problem>; expected
  ///         <range>") for the first out-of-range or inconsistent value.
  void ValidateOrThrow(const std::string& key_prefix = "") const;
};

/// an entry of the registry: what the code outside effects/types/ needs of a type without
/// naming it. made from the type's hooks (effect_type.h).
struct EffectTypeInfo {
  std::string name;  ///< world-file name, P::kTypeName
  size_t index = 0;  ///< position in EffectParams (keys the effect's random streams)
  /// the type's world-file keys (P::Keys()), after the common ones.
  std::vector<std::string_view> keys;
  /// an EffectConfig holding this type with its parameters read from `r` (P::Read).
  void (*read)(const EffectParamReader& r, EffectConfig* e) = nullptr;
};

/// every registered effect type, in EffectParams order.
const std::vector<EffectTypeInfo>& EffectTypes();
/// the type named `name`, or null.
const EffectTypeInfo* FindEffectType(std::string_view name);
/// every world-file type name, in registry order.
const std::vector<std::string>& EffectTypeNames();

/// the grid-fluid step of effects that run a fluid (fire, plume smoke), for the run's work
/// estimate; nullopt for the others.
std::optional<double> EffectFluidDtSec(const EffectConfig& e);

/// the effect bound to `ctx.scene` (the type's Bind).
/// @throws ConfigError from the type (unknown light or body, unreadable .vdb file).
std::unique_ptr<EffectInstance> BindEffect(const EffectConfig& e, const EffectBindContext& ctx);

/// validates every effect (keys "effects[i].<key>") and the cross-effect rules: unique
/// names, and each type's CheckReferences (wetness.rain and sparks.fire naming effects of
/// that type).
/// @param file     file named in errors ("" = none)
/// @param line_of  optional: 1-based line of a key path, or 0 when unknown
/// @throws ConfigError(file, line_of(key), key, problem) on the first violation.
void ValidateEffectsOrThrow(const std::vector<EffectConfig>& effects, const std::string& file = "",
                            const std::function<int(const std::string&)>& line_of = {});

}  // namespace penumbra
