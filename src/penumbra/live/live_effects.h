#pragma once
// live changes of a running world's adverse conditions (set through the bridges and
// the viewer while the run goes on): a whole adversity preset,
// one block of the live preset (fog MOR, smoke extinction, rain and snow rate, light scale,
// NPC count), or the parameters of one effect, changed, added or removed while the run goes on.
//
// threading and determinism: the Set* calls come from any thread (a bridge's, the viewer's).
// each is checked in full on the caller's thread (spec, keys, ranges, the effects bound to the
// scene, NPC bodies) and throws before anything changes; an accepted change is queued and
// applied on the loop thread at the next step boundary, before any sink sees that step (this
// sink is the loop's first), so every camera frame and sensor output of that step and later
// sees it, and none before. in lockstep the loop stands between two steps while a request is
// served, so a change requested after step n is applied at step n + 1, the first step the
// client asks for next: the same requests at the same steps give the same images.
//
// what a change does (session/effects_stage.h): the run's effects are the world's own effects
// (as changed live), then the effects planned from the live adversity preset, as at the start
// of a run; the agents are the world's, then the preset's NPCs. every random stream is keyed by
// the effect's name and type (effects/effects_engine.h), so a change leaves the other effects'
// particles and noise where they were; stateful fluids (plume smoke, fire) are re-stepped from
// t = 0 with their new parameters. NPCs: a run cannot add bodies to its loaded model (the
// physics state and every index would change mid-run), so a run has the NPC bodies of the preset it
// started with, plus, in a live run, parked bodies for the NPCs of the bundled presets
// (SessionOptions::reserve_live_npcs); a change may move them onto other paths or park them (100 m
// below the floor) but not add more.
//
// recording: every applied change is handed to the on_applied callback (LiveControl records
// it as a run-log event "live" with the change's JSON, docs/run-log.md "Live changes"), and a
// replay schedules the recorded changes at their steps (ScheduleRecorded), which gives the
// same effects frame for frame.

#include <atomic>
#include <cstdint>
#include <deque>
#include <filesystem>
#include <functional>
#include <memory>
#include <mutex>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "penumbra/core/pose.h"
#include "penumbra/effects/agent_path.h"
#include "penumbra/effects/effect_config.h"
#include "penumbra/effects/effects_engine.h"
#include "penumbra/pipeline/sink.h"
#include "penumbra/session/session.h"
#include "penumbra/world/adversity_edit.h"

namespace penumbra {

/// receives each change applied, on the loop thread: the step and sim time (s) it applies
/// from and the change as recorded (LiveEffects::SetAdversity / SetEffect).
using LiveChangeCallback =
    std::function<void(int64_t step, double time_sec, const nlohmann::json& change)>;

/// the adversity preset of a run as requested so far (LiveEffects::requested_adversity): what
/// every step from the next boundary on sees, once the queued changes are applied.
struct RequestedAdversity {
  std::optional<AdversityPreset> preset;  ///< the live preset; nullopt or empty() = none
  std::string name = "none";  ///< the preset's name as chosen (bundled name or NAME of a file)
  bool edited = false;        ///< a block (fog, smoke, ...) was changed since it was chosen
  int64_t changes = 0;        ///< accepted changes so far (grows by one per change)
};

/// the live adverse conditions of one Session; a pipeline sink that applies the queued
/// changes. register it as the loop's first sink.
class LiveEffects : public Sink {
 public:
  /// SinkStage::kLiveChanges: a change applies before any other sink sees its step.
  SinkStage stage() const override { return SinkStage::kLiveChanges; }
  /// the conditions as `session` set them up. `session` must outlive this object; build it
  /// before the loop starts (it reads the static bodies' poses from the simulation).
  explicit LiveEffects(Session& session);
  ~LiveEffects() override;
  LiveEffects(const LiveEffects&) = delete;
  LiveEffects& operator=(const LiveEffects&) = delete;

  /// replaces the adversity preset with one a client asked for (the bridges and the viewer):
  /// `preset_spec` is a bundled name, or FILE.yaml / FILE.yaml#NAME inside the world file's
  /// folder, named relative to it (world/adversity_preset.h LoadClientAdversityPreset: no
  /// absolute path, no "..", no symbolic link, ends in .yaml, at most 1 MiB); "none" (or "")
  /// clears it. the world's own effects stay. a preset file that does not parse is refused
  /// naming its line and the rule; its full error (with the values it quotes) goes to the
  /// server's log only. recorded as {"op": "set_adversity", "spec": <the file's path on the
  /// server, #NAME>}.
  /// @throws ConfigError("", 0, "adversity", ...) for an unknown bundled preset;
  ///         ConfigError("", 0, "preset", ...) for a file path the rules refuse or a bad preset
  ///         file (no content quoted); ConfigError("", 0, "npcs", ...) when it asks for more
  ///         NPCs than the run has bodies.
  void SetAdversity(const std::string& preset_spec);

  /// changes, adds or removes one effect; `params` is a JSON object (or null). what
  /// `effect_name` names, in this order:
  ///   - an effect of the world (or one added live): `params` holds world-file keys of its
  ///     type and start_sec, stop_sec, fade_in_sec, fade_out_sec, region {min, max}
  ///     (docs/effects.md); the keys given replace those values, the others keep theirs
  ///     (for fog and dust, a given mor_m or sigma_t_per_m replaces the other); null
  ///     removes the effect.
  ///   - a block of the adversity preset (fog, dust, smoke, rain, snow, lights, npcs;
  ///     world/adversity_preset.h): `params` holds keys of that block (e.g. {"mor_m": 20},
  ///     {"sigma_t_per_m": 1.5}, {"rate_mm_h": 10}, {"scale": 0.3}, {"people": 1}), merged
  ///     into the live preset's block, which is then placed in the world as at the start
  ///     of a run (session/effects_stage.h); null removes the block.
  ///   - "adversity_<what>" (an effect planned from the preset): refused; change the block.
  ///   - any other name: a new effect; `params` must hold "type" (a world-file effect type)
  ///     and that type's keys. it is added after the world's effects.
  /// recorded as {"op": "set_effect", "name": <effect_name>, "params": <params>}.
  /// @throws ConfigError("", 0, "effects.<name>.<key>" or "<block>.<key>", ...) naming the
  ///         field and what was expected (unknown key, wrong type, out of range, a missing
  ///         type, a removal of something that is not there, more NPCs than the run has
  ///         bodies, an unknown light or body name), before anything changes.
  void SetEffect(const std::string& effect_name, const nlohmann::json& params);

  /// a recorded change (an event payload written through on_applied) to apply at `step`
  /// (a replay); checked as SetAdversity / SetEffect check. schedule in recorded order.
  /// @throws ConfigError as those, or ConfigError("", 0, "op", ...) for an unknown op.
  void ScheduleRecorded(int64_t step, const nlohmann::json& change);

  /// called on the loop thread for every change applied (set before the loop starts).
  void set_on_applied(LiveChangeCallback callback) { on_applied_ = std::move(callback); }

  /// changes requested and not applied yet.
  size_t pending() const;
  /// the adversity preset as requested so far: the run's own at the start, then after every
  /// accepted SetAdversity / SetEffect / ScheduleRecorded (applied or still queued; a queued
  /// change applies at the next step boundary). thread-safe.
  RequestedAdversity requested_adversity() const;
  /// the step the loop last reached (its Wants), -1 before the first (thread-safe).
  int64_t step() const { return step_.load(std::memory_order_acquire); }

  /// applies the queued changes due at `step` (all requests, and recorded changes scheduled
  /// at or before `step`); wants no snapshot.
  SnapshotContent Wants(int64_t step, double time_sec) override;
  void OnSnapshot(const std::shared_ptr<const WorldSnapshot>&) override {}

 private:
  // the conditions as requested: the world's own effects and the preset
  struct State {
    std::vector<EffectConfig> own;
    std::optional<AdversityPreset> preset;
    std::string preset_name = "none";
    bool preset_edited = false;
  };
  struct Change {
    int64_t step = -1;  // -1 = the next step boundary
    nlohmann::json record;
    std::vector<EffectConfig> effects;
    std::vector<AgentConfig> agents;
    std::optional<AdversityPreset> preset;
    std::unique_ptr<EffectsEngine> engine;
  };

  // the effects and agents of `s`, checked (bound to the scene); mu_ held
  Change Plan(const State& s) const;
  void Queue(State s, nlohmann::json record, int64_t step);
  State EditEffect(const std::string& name, const nlohmann::json& params) const;

  Session& session_;
  std::filesystem::path preset_folder_;  // the world file's folder ("" = none): preset files
  std::vector<Pose> X_WB_start_;         // every body's pose at the start (the static ones stay)
  std::vector<Eigen::Vector3d> robot_starts_;
  std::vector<int> agent_mocap_ids_;
  mutable std::mutex mu_;
  State requested_;
  std::deque<Change> queue_;
  int64_t changes_ = 0;
  LiveChangeCallback on_applied_;
  std::atomic<int64_t> step_{-1};
};

}  // namespace penumbra
