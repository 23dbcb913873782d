#include "penumbra/live/live_effects.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <filesystem>
#include <utility>
#include <variant>

#include "penumbra/compose/agent_bodies.h"
#include "penumbra/core/error.h"
#include "penumbra/live/json_effect_reader.h"
#include "penumbra/physics/simulation.h"

namespace penumbra {
namespace {

namespace fs = std::filesystem;

const std::vector<std::string_view> kCommonKeys = {"type",        "start_sec",    "stop_sec",
                                                   "fade_in_sec", "fade_out_sec", "region"};

bool IsBlock(const std::string& name) {
  const std::vector<std::string>& blocks = AdversityPresetBlocks();
  return std::find(blocks.begin(), blocks.end(), name) != blocks.end();
}

// default parameters of the effect type at `index` of EffectParams
template <size_t... I>
EffectParams DefaultParams(size_t index, std::index_sequence<I...>) {
  EffectParams p;
  ((I == index ? (void)p.template emplace<I>() : (void)0), ...);
  return p;
}

// the common keys and the type's keys of `params_in` read into `e` (keys not given keep theirs)
void ReadInto(const nlohmann::json& params_in, const std::string& path, EffectConfig* e) {
  nlohmann::json params = params_in;
  // light_event's `light` is required by its reader: a change keeps the light it names
  if (const auto* ev = std::get_if<LightEventParams>(&e->params);
      ev && !ev->light.empty() && !params.contains("light"))
    params["light"] = ev->light;
  JsonEffectReader r(params, path);
  std::vector<std::string_view> keys = kCommonKeys;
  keys.insert(keys.end(), e->type().keys.begin(), e->type().keys.end());
  r.ExpectKeys(keys);
  r.Num("start_sec", &e->start_sec);
  r.Num("stop_sec", &e->stop_sec);
  r.Num("fade_in_sec", &e->fade_in_sec);
  r.Num("fade_out_sec", &e->fade_out_sec);
  if (r.Has("region")) {
    const nlohmann::json& region = params.at("region");
    if (region.is_null()) {
      e->region.reset();
    } else {
      JsonEffectReader rr(region, path + ".region");
      rr.ExpectKeys({"min", "max"});
      BoxRegion b;
      b.min_W = rr.Vector3("min");
      b.max_W = rr.Vector3("max");
      e->region = b;
    }
  }
  // fog and dust take one of mor_m and sigma_t_per_m: the one given replaces the other
  const auto extinction = [&](ExtinctionSpec* x) {
    if (r.Has("mor_m")) x->sigma_t_per_m.reset();
    if (r.Has("sigma_t_per_m")) x->mor_m.reset();
  };
  if (auto* fog = std::get_if<FogParams>(&e->params)) extinction(&fog->extinction);
  if (auto* dust = std::get_if<DustParams>(&e->params)) extinction(&dust->extinction);
  std::visit([&](auto& p) { p.Read(r); }, e->params);
}

}  // namespace

LiveEffects::LiveEffects(Session& session) : session_(session) {
  Simulation& sim = session.sim();
  X_WB_start_ = sim.Snapshot(Simulation::SnapshotContent::kPoses).X_WB;
  for (const ModelConfig& m : session.world().models)
    if (m.is_robot) robot_starts_.push_back(m.pose.xyz);
  const std::vector<std::string> mocap = sim.MocapBodyNames();
  // every body of an agent: its root and its parts (limbs, wheels)
  for (size_t i = 0; i < mocap.size(); ++i)
    for (const std::string& agent : session.effects().agent_bodies())
      if (IsAgentBodyOf(mocap[i], agent)) {
        agent_mocap_ids_.push_back(static_cast<int>(i));
        break;
      }
  // preset files clients name are read from inside the world file's folder only
  if (!session.world().file.empty()) {
    std::error_code ec;
    const fs::path world_file = fs::absolute(session.world().file, ec);
    if (!ec) preset_folder_ = world_file.parent_path();
  }
  requested_.own = session.world().effects;
  requested_.preset = session.effects().preset();
  if (requested_.preset && !requested_.preset->name.empty())
    requested_.preset_name = requested_.preset->name;
}

LiveEffects::~LiveEffects() = default;

LiveEffects::Change LiveEffects::Plan(const State& s) const {
  Change c;
  c.effects = s.own;
  c.agents = session_.world().agents;
  c.preset = s.preset;
  if (s.preset && !s.preset->empty())
    PlanAdversityPreset(*s.preset, session_.scene(), X_WB_start_, robot_starts_,
                        RobotStartYaws(session_.world()), session_.effects().seed(), &c.effects,
                        &c.agents, session_.effects().sites());
  const std::vector<std::string>& bodies = session_.effects().agent_bodies();
  for (const AgentConfig& a : c.agents)
    if (std::find(bodies.begin(), bodies.end(), a.name) == bodies.end())
      throw ConfigError("", 0, "npcs",
                        "NPC '" + a.name +
                            "' has no body in this run: a run keeps the NPC bodies of the preset "
                            "it started with (a run cannot add bodies to its loaded model); "
                            "expected at most those (" +
                            std::to_string(bodies.size() - session_.world().agents.size()) +
                            " NPCs)");
  ValidateAgentsOrThrow(c.agents, "");
  try {
    ValidateEffectsOrThrow(c.effects);
    // bound here, so that an unknown light or body name fails the request, not the loop
    if (!c.effects.empty())
      c.engine =
          std::make_unique<EffectsEngine>(c.effects, session_.effects().seed(), session_.scene());
  } catch (const ConfigError& e) {
    // "effects[3].light" -> "effects.<name>.light": a live request names effects by name
    const std::string& key = e.key();
    const size_t close = key.find(']');
    if (key.rfind("effects[", 0) != 0 || close == std::string::npos) throw;
    const size_t i = std::stoul(key.substr(8, close - 8));
    if (i >= c.effects.size()) throw;
    throw ConfigError("", 0, "effects." + c.effects[i].name + key.substr(close + 1), e.problem());
  }
  return c;
}

void LiveEffects::Queue(State s, nlohmann::json record, int64_t step) {
  Change c = Plan(s);
  c.step = step;
  c.record = std::move(record);
  requested_ = std::move(s);
  queue_.push_back(std::move(c));
  ++changes_;
}

void LiveEffects::SetAdversity(const std::string& preset_spec) {
  const std::string spec = preset_spec.empty() ? std::string("none") : preset_spec;
  std::string detail;
  ClientAdversityPreset requested;
  try {
    requested = LoadClientAdversityPreset(spec, preset_folder_, &detail);
  } catch (const ConfigError&) {
    // the client gets the file's name, line and rule; the server's user the whole error
    if (!detail.empty()) spdlog::warn("set_adversity: {}", detail);
    throw;
  }
  std::lock_guard<std::mutex> lock(mu_);
  State s = requested_;
  s.preset = std::move(requested.preset);
  s.preset_name = s.preset && !s.preset->name.empty() ? s.preset->name : spec;
  s.preset_edited = false;
  Queue(std::move(s), {{"op", "set_adversity"}, {"spec", requested.spec}}, -1);
}

LiveEffects::State LiveEffects::EditEffect(const std::string& name,
                                           const nlohmann::json& params) const {
  State s = requested_;
  const std::string path = "effects." + name;
  if (!params.is_null() && !params.is_object())
    throw ConfigError("", 0, path, "got " + params.dump() + "; expected an object or null");
  const auto it = std::find_if(s.own.begin(), s.own.end(),
                               [&](const EffectConfig& e) { return e.name == name; });
  if (it != s.own.end()) {
    if (params.is_null()) {
      s.own.erase(it);
      return s;
    }
    if (params.contains("type") && params["type"] != it->type_name())
      throw ConfigError("", 0, path + ".type",
                        "got " + params["type"].dump() + "; expected \"" + it->type_name() +
                            "\" (an effect keeps its type; remove it and add another)");
    ReadInto(params, path, &*it);
    it->ValidateOrThrow(path);
    return s;
  }
  if (IsBlock(name)) {
    AdversityPreset base;
    if (s.preset && !s.preset->empty()) {
      base = *s.preset;
    } else {
      base.name = "live";  // run.json's adversity label: "live (live changes)"
      base.file = "live changes";
    }
    s.preset = EditAdversityPreset(base, name, params.dump());
    s.preset_edited = true;
    return s;
  }
  if (name.rfind("adversity_", 0) == 0)
    throw ConfigError("", 0, path,
                      "is planned from the adversity preset; expected a change of its block "
                      "(fog, dust, smoke, rain, snow, lights, npcs) or of the preset");
  if (params.is_null())
    throw ConfigError("", 0, path, "no such effect to remove; expected the name of an effect");
  if (!params.contains("type"))
    throw ConfigError("", 0, path + ".type",
                      "missing; a new effect needs its type (one of the world file's effect "
                      "types, docs/effects.md)");
  EffectConfig e;
  e.name = name;
  std::vector<std::string_view> types;
  for (const std::string& t : EffectTypeNames()) types.push_back(t);
  const std::string type = JsonEffectReader(params, path).Enum("type", types);
  e.params = DefaultParams(FindEffectType(type)->index,
                           std::make_index_sequence<std::variant_size_v<EffectParams>>());
  ReadInto(params, path, &e);
  e.ValidateOrThrow(path);
  s.own.push_back(std::move(e));
  return s;
}

void LiveEffects::SetEffect(const std::string& effect_name, const nlohmann::json& params) {
  std::lock_guard<std::mutex> lock(mu_);
  State s = EditEffect(effect_name, params);
  Queue(std::move(s), {{"op", "set_effect"}, {"name", effect_name}, {"params", params}}, -1);
}

void LiveEffects::ScheduleRecorded(int64_t step, const nlohmann::json& change) {
  const std::string op = change.value("op", "");
  std::lock_guard<std::mutex> lock(mu_);
  State s;
  nlohmann::json record;
  if (op == "set_adversity" && change.contains("spec") && change["spec"].is_string()) {
    const std::string spec = change["spec"].get<std::string>();
    s = requested_;
    s.preset = LoadAdversityPreset(spec);
    s.preset_name = s.preset->name.empty() ? spec : s.preset->name;
    s.preset_edited = false;
    record = {{"op", op}, {"spec", spec}};
  } else if (op == "set_effect" && change.contains("name") && change["name"].is_string()) {
    const std::string name = change["name"].get<std::string>();
    const nlohmann::json params = change.value("params", nlohmann::json());
    s = EditEffect(name, params);
    record = {{"op", op}, {"name", name}, {"params", params}};
  } else {
    throw ConfigError("", 0, "op",
                      "unknown live change " + change.dump() +
                          "; expected {\"op\": \"set_adversity\", \"spec\": ...} or {\"op\": "
                          "\"set_effect\", \"name\": ..., \"params\": ...}");
  }
  Queue(std::move(s), std::move(record), step);
}

RequestedAdversity LiveEffects::requested_adversity() const {
  std::lock_guard<std::mutex> lock(mu_);
  RequestedAdversity r;
  r.preset = requested_.preset;
  r.name = requested_.preset_name;
  r.edited = requested_.preset_edited;
  r.changes = changes_;
  return r;
}

size_t LiveEffects::pending() const {
  std::lock_guard<std::mutex> lock(mu_);
  return queue_.size();
}

SnapshotContent LiveEffects::Wants(int64_t step, double time_sec) {
  std::vector<Change> due;
  {
    std::lock_guard<std::mutex> lock(mu_);
    while (!queue_.empty() && queue_.front().step <= step) {
      due.push_back(std::move(queue_.front()));
      queue_.pop_front();
    }
  }
  for (Change& c : due) {
    session_.effects().Replace(std::move(c.effects), std::move(c.agents), std::move(c.preset),
                               std::move(c.engine));
    // the agent bodies onto their new paths (or parked) from this step on
    session_.sim().ApplyMocapDrivers(agent_mocap_ids_);
    spdlog::info("live change at step {} (t = {:.6g} s): {}", step, time_sec, c.record.dump());
    if (on_applied_) on_applied_(step, time_sec, c.record);
  }
  step_.store(step, std::memory_order_release);
  return SnapshotContent::kNone;
}

}  // namespace penumbra
