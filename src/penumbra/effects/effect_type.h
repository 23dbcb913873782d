#pragma once
// what an effect type implements (the contract of the effects registry, effect_types.h).
//
// an effect type is a parameter struct P in effects/types/<name>.{h,cc} and one entry in
// the EffectParams variant of effect_types.h. P is plain data with defaults plus:
//
//   static constexpr std::string_view kTypeName;   // world-file name, "fog"
//   static std::vector<std::string_view> Keys();     // its world-file keys (next to name,
//                                                    // type, start_sec, ... in the entry)
//   void Read(const EffectParamReader& r);           // reads the keys that are present
//   void Validate(const EffectConfig& e, EffectChecker* c) const;  // ranges, first problem
//   std::unique_ptr<EffectInstance> Bind(const EffectConfig& e,
//                                        const EffectBindContext& ctx) const;
//
// and optionally
//
//   std::optional<EffectProblem> CheckReferences(const std::vector<EffectConfig>&) const;
//       names of other effects it refers to (wetness -> rain, sparks -> fire)
//   std::optional<double> FluidDtSec() const;
//       the internal step of a grid fluid it runs, for the run's work estimate
//
// keys in Read and Validate are relative to the effect entry ("rate_mm_h",
// "emitters[0].position"); the world reader and ValidateEffectsOrThrow add "effects[i]." and
// the line. nothing here depends on YAML: world/effects_reader.cc implements the reader.

#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "penumbra/core/pose.h"
#include "penumbra/scene/effects_frame.h"
#include "penumbra/scene/scene_description.h"

namespace penumbra {

struct EffectConfig;
class ThreadPool;

/// a problem found by validation: the world-file key relative to the effect entry ("rate_mm_h",
/// "region.min", "emitters[0].position") and the message with the valid range.
struct EffectProblem {
  std::string key;
  std::string message;
};

/// the parameter keys of one effect entry (or of one element of a list inside it), as
/// the world reader provides them. every read records the key's line for later errors.
/// keys are relative to this node.
class EffectParamReader {
 public:
  virtual ~EffectParamReader() = default;

  /// whether key `k` is present.
  virtual bool Has(std::string_view k) const = 0;
  /// required values.
  /// @throws ConfigError(file, line, "<path>.<k>", ...) when the key is missing or has the
  ///         wrong type ("expected a number", "expected a list of 3 numbers", ...).
  virtual double Double(std::string_view k) const = 0;
  virtual int Integer(std::string_view k) const = 0;
  virtual Eigen::Vector3d Vector3(std::string_view k) const = 0;
  virtual std::string String(std::string_view k) const = 0;
  virtual bool Boolean(std::string_view k) const = 0;
  /// one of `valid`. @throws ConfigError "unknown value '<v>'; expected one of: ..." otherwise.
  virtual std::string Enum(std::string_view k,
                           const std::vector<std::string_view>& valid) const = 0;
  /// the elements of the list at `k` (each recorded with its line).
  /// @throws ConfigError when `k` is missing or not a list.
  virtual std::vector<std::unique_ptr<EffectParamReader>> List(std::string_view k) const = 0;
  /// @throws ConfigError when this node is not a map or has a key not in `keys`
  ///         ("unknown key '<k>'; expected one of: ...").
  virtual void ExpectKeys(const std::vector<std::string_view>& keys) const = 0;
  /// `path` made absolute against the world file's folder (unchanged when absolute), normalised.
  virtual std::string ResolvePath(const std::string& path) const = 0;

  /// optional values: `*v` is set only when the key is present.
  void Num(std::string_view k, double* v) const {
    if (Has(k)) *v = Double(k);
  }
  void Int(std::string_view k, int* v) const {
    if (Has(k)) *v = Integer(k);
  }
  void Vec(std::string_view k, Eigen::Vector3d* v) const {
    if (Has(k)) *v = Vector3(k);
  }
  void Str(std::string_view k, std::string* v) const {
    if (Has(k)) *v = String(k);
  }
  void Bool(std::string_view k, bool* v) const {
    if (Has(k)) *v = Boolean(k);
  }
};

/// an interval of valid values; open ends exclude the bound.
struct EffectRange {
  static constexpr double kInf = std::numeric_limits<double>::infinity();
  double lo = -kInf, hi = kInf;
  bool lo_open = true, hi_open = true;

  static EffectRange Closed(double lo, double hi) { return {lo, hi, false, false}; }
  static EffectRange OpenClosed(double lo, double hi) { return {lo, hi, true, false}; }
  static EffectRange ClosedOpen(double lo, double hi) { return {lo, hi, false, true}; }
  static EffectRange Open(double lo, double hi) { return {lo, hi, true, true}; }
  static EffectRange AtLeast(double lo) { return {lo, kInf, false, true}; }
  static EffectRange Above(double lo) { return {lo, kInf, true, true}; }
  static EffectRange Finite() { return {-kInf, kInf, true, true}; }

  /// v inside (NaN never; an infinite v only when it is a closed infinite end).
  bool Contains(double v) const;
  /// "[0, 1]", "> 0", ">= 1", "a finite number".
  std::string ToString() const;
};

/// collects the first problem of an effect (later checks are ignored once one failed).
class EffectChecker {
 public:
  bool ok() const { return !problem_; }
  const std::optional<EffectProblem>& problem() const { return problem_; }

  /// records {key, message} unless a problem was recorded before.
  void Fail(const std::string& key, const std::string& message);
  /// "<v> is out of range; expected <r>" unless r contains v.
  void In(const std::string& key, double v, EffectRange r);
  /// "[x, y, z] is out of range; expected 3 numbers, each <r>" unless r contains each.
  void In3(const std::string& key, const Eigen::Vector3d& v, EffectRange r);
  /// Henyey-Greenstein asymmetry: (-1, 1).
  void Phase(const std::string& key, double g) { In(key, g, EffectRange::Open(-1, 1)); }

  /// shortest round-trip decimal of v ("0.1", "inf").
  static std::string Num(double v);
  /// "[x, y, z]" with Num.
  static std::string Vec(const Eigen::Vector3d& v);

 private:
  std::optional<EffectProblem> problem_;
};

/// what a type's Bind gets: the scene the effect renders into and the run's other effects.
struct EffectBindContext {
  const SceneDescription& scene;
  /// all effects of the run, in order; lives as long as the instance (EffectsEngine owns it).
  const std::vector<EffectConfig>& effects;
  size_t index = 0;  ///< this effect's index in `effects`
  /// the effect's random-stream key: HashKeys(seed, FNV-1a(name), type index).
  uint64_t key = 0;
  std::string key_prefix;  ///< "effects[<index>]", for errors
  std::string who;         ///< "effect '<name>' (<type>): ", for error messages
};

/// what an instance's Evaluate gets at one sim time.
struct EffectEvalContext {
  double time_sec = 0;
  double weight = 0;                        ///< EffectConfig::Weight(time_sec)
  Eigen::Vector3d viewer_W{0, 0, 0};        ///< viewer position, world frame, m
  const std::vector<Pose>* X_WB = nullptr;  ///< body poses, or null
  std::function<ThreadPool*()> pool;        ///< threads for parallel work, made on use
};

/// one effect bound to a scene: its state (fluid grids, particle tables, light indices).
class EffectInstance {
 public:
  virtual ~EffectInstance() = default;
  /// adds the effect's contribution at ctx.time_sec to `frame` (media, particles, lights).
  virtual void Evaluate(const EffectEvalContext& ctx, EffectsFrame* frame) = 0;
  /// true when Evaluate writes EffectsFrame::light_intensity_scale (the engine then fills
  /// it with one 1.0 per scene light before the first instance runs).
  virtual bool ScalesSceneLights() const { return false; }
};

}  // namespace penumbra
