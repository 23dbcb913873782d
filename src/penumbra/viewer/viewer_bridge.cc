#include "penumbra/viewer/viewer_bridge.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <charconv>
#include <chrono>
#include <condition_variable>
#include <deque>
#include <filesystem>
#include <map>
#include <mutex>
#include <set>
#include <thread>

#include "penumbra/command/command_dispatcher.h"
#include "penumbra/command/run_control.h"
#include "penumbra/control/controller_capabilities.h"
#include "penumbra/core/error.h"
#include "penumbra/physics/simulation.h"
#include "penumbra/sensors/lidar_scanner.h"
#include "penumbra/live/live_control.h"
#include "penumbra/session/npc_map_json.h"
#include "penumbra/session/session.h"
#include "penumbra/viewer/image_maps.h"
#include "penumbra/viewer/viewer_messages.h"
#include "penumbra/viewer/web_root.h"
#include "penumbra/viewer/web_server.h"
#include "penumbra/world/adversity_preset.h"

namespace penumbra {

using nlohmann::json;

void ViewerOptions::ValidateOrThrow() const {
  if (host.empty()) throw ConfigError("", 0, "--viewer", "empty host; expected HOST:PORT");
  if (port < 0 || port > 65535)
    throw ConfigError("", 0, "--viewer", fmt::format("port {} is out of range 0..65535", port));
  if (!(state_hz > 0 && state_hz <= 1000))
    throw ConfigError("", 0, "viewer.state_hz",
                      fmt::format("{}; expected a rate in (0, 1000] Hz", state_hz));
  for (const std::string& o : allowed_origins) NormalizeOrigin(o);
  jpeg.ValidateOrThrow();
}

void ParseViewerAddress(const std::string& spec, ViewerOptions* options) {
  if (spec.empty()) return;
  std::string host = options->host, port_text = spec;
  if (spec.front() == '[') {  // [v6]:port
    const size_t close = spec.find(']');
    if (close == std::string::npos || close + 1 >= spec.size() || spec[close + 1] != ':')
      throw ConfigError(
          "", 0, "--viewer",
          "'" + spec + "' is not [IPv6]:PORT; expected HOST:PORT, e.g. 127.0.0.1:8080");
    host = spec.substr(1, close - 1);
    port_text = spec.substr(close + 2);
  } else if (const size_t colon = spec.rfind(':'); colon != std::string::npos) {
    if (colon > 0) host = spec.substr(0, colon);
    port_text = spec.substr(colon + 1);
  }
  int port = -1;
  const auto r = std::from_chars(port_text.data(), port_text.data() + port_text.size(), port);
  if (port_text.empty() || r.ec != std::errc() || r.ptr != port_text.data() + port_text.size() ||
      port < 0 || port > 65535)
    throw ConfigError(
        "", 0, "--viewer",
        "'" + spec + "': port '" + port_text +
            "' is not an integer in 0..65535; expected HOST:PORT, e.g. 127.0.0.1:8080");
  if (host.empty()) throw ConfigError("", 0, "--viewer", "'" + spec + "': empty host");
  options->host = host;
  options->port = port;
}

namespace {

// the world's preset as a client sees it: a bundled name as it is, a preset file by its file
// name (and #NAME) only, so that no client learns the server's folders
std::string PresetForClient(const std::string& spec) {
  if (spec.empty()) return "none";
  const size_t hash = spec.find('#');
  const std::string file = spec.substr(0, hash);
  if (file.find('/') == std::string::npos) return spec;
  return std::filesystem::path(file).filename().string() +
         (hash == std::string::npos ? "" : spec.substr(hash));
}

using Clock = std::chrono::steady_clock;

double Seconds(Clock::duration d) { return std::chrono::duration<double>(d).count(); }

json CommandErrorReply(const json& cmd, const json* id, const char* code, const std::string& field,
                       const std::string& message) {
  return ErrorReply(cmd, id, CommandError(code, field, message));
}

// counts events per wall-clock second over a sliding ~1 s window
class RateMeter {
 public:
  void Add(int64_t n = 1) {
    std::lock_guard<std::mutex> lock(mu_);
    count_ += n;
  }
  double Rate() {
    std::lock_guard<std::mutex> lock(mu_);
    const Clock::time_point now = Clock::now();
    const double dt = Seconds(now - since_);
    if (dt >= 1.0) {
      rate_ = count_ / dt;
      count_ = 0;
      since_ = now;
    }
    return rate_;
  }

 private:
  std::mutex mu_;
  int64_t count_ = 0;
  Clock::time_point since_ = Clock::now();
  double rate_ = 0;
};

// the viewer's kinds of a camera stream and whether a frame has what each needs
bool FrameHas(const CameraFrame& f, const std::string& kind) {
  if (kind == "rgb") return !f.rgb.empty();
  if (kind == "depth") return !f.depth_m.empty();
  if (kind == "segmentation") return !f.rgb.empty() && !f.geom_id.empty();
  return false;
}

class ViewerBridge : public RunBridge {
 public:
  ViewerBridge(const RunBridgeContext& ctx, ViewerOptions options)
      : session_(ctx.session),
        world_(ctx.world),
        dispatcher_(ctx.dispatcher),
        control_(ctx.control),
        model_info_(ctx.model_info),
        options_(std::move(options)) {
    options_.ValidateOrThrow();
    BuildStatic();
    WebServerOptions so;
    so.host = options_.host;
    so.port = options_.port;
    so.web_root = options_.web_root.empty() ? FindWebRoot() : options_.web_root;
    so.max_message_bytes = options_.max_message_bytes;
    so.max_clients = options_.max_clients;
    so.allowed_origins = options_.allowed_origins;
    WebServerHandlers h;
    h.on_open = [this](int client) { return OnOpen(client); };
    h.on_message = [this](int client, std::string_view text) { return OnMessage(client, text); };
    h.on_close = [this](int client) { OnClose(client); };
    server_ = std::make_unique<WebServer>(so, std::move(h));
    // the URL holds the secret token: it is printed here only, never sent to a client
    spdlog::info("viewer: open {} in a browser (serving {})", server_->url(), so.web_root);
    if (options_.on_listening) options_.on_listening(server_->url());
    encoder_ = std::thread([this] { EncoderLoop(); });
  }

  ~ViewerBridge() override {
    StopEncoder();
    server_.reset();  // handlers use this object: stop the server first
  }

  void OnStart(const LoopStart& start) override { last_state_wall_ = Clock::now(); }

  SnapshotContent Wants(int64_t step, double time_sec) override {
    steps_.Add();
    // an adversity change no page was told of (another client's): the new state, once
    if (LiveControl* live = dispatcher_.live();
        live && clients_.load() > 0 &&
        live->effects().requested_adversity().changes > published_changes_.load())
      PublishStatus(json::object());
    // the first step's state is kept for pages that connect later (e.g. to a paused run)
    if (clients_.load() == 0 && state_step_ >= 0) return SnapshotContent::kNone;
    const Clock::time_point now = Clock::now();
    // every step while paused (single steps show exactly), else at state_hz of wall time
    if (state_step_ < 0 || control_.paused() ||
        Seconds(now - last_state_wall_) >= 1.0 / options_.state_hz) {
      last_state_wall_ = now;
      state_step_ = step;
      return SnapshotContent::kFull;
    }
    return SnapshotContent::kNone;
  }

  void OnSnapshot(const std::shared_ptr<const WorldSnapshot>& snapshot) override {
    if (snapshot->step != state_step_ || snapshot->X_WB.empty()) return;
    std::lock_guard<std::mutex> lock(mu_);
    pending_state_ = snapshot;
    cv_.notify_one();
  }

  void OnFinish(const LoopFinish& finish) override {
    ended_ = true;
    PublishStatus(json{{"step", finish.step}, {"time_sec", finish.time_sec}});
    StopEncoder();
  }

  void OnCameraFrame(const std::shared_ptr<const CameraFrame>& frame) override {
    rendered_.Add();
    bool wanted = false;
    {
      std::lock_guard<std::mutex> lock(sub_mu_);
      wanted = wanted_cameras_.count(frame->camera) > 0;
    }
    std::lock_guard<std::mutex> lock(mu_);
    last_frames_[frame->camera] = frame;  // for a page that subscribes later
    if (!wanted) return;
    pending_frames_[frame->camera] = frame;
    cv_.notify_one();
  }

  void OnSensorSample(const SensorSample& s) override {
    if (clients_.load() == 0) return;
    std::lock_guard<std::mutex> lock(sig_mu_);
    if (s.kind == SensorKind::kImu && s.values.size() >= 6) {
      static const char* kAxes[6] = {"accel_x", "accel_y", "accel_z", "gyro_x", "gyro_y", "gyro_z"};
      for (int k = 0; k < 6; ++k) sensor_signals_["imu/" + s.sensor + "/" + kAxes[k]] = s.values[k];
    } else if (s.kind == SensorKind::kMujoco && s.columns) {
      for (size_t k = 0; k < s.values.size() && k < s.columns->size(); ++k)
        sensor_signals_["sensor/" + s.sensor + "/" + (*s.columns)[k]] = s.values[k];
    } else if (s.kind == SensorKind::kLidar && s.scan) {
      pending_lidar_[s.sensor] = s;
    }
  }

 private:
  // ---- static parts: hello and scene ----
  void BuildStatic() {
    Simulation& sim = session_.sim();
    const double dt = sim.timestep();
    double period = dt;
    json teleop = json::array(), waypoint = json::array(), joint_controls = json::array();
    bool teleop_vy = false;
    for (const json& c : model_info_.value("controllers", json::array())) {
      const std::string robot = c.value("robot", "");
      const int index = c.value("index", -1);
      bool has_twist = false;
      for (const json& cmd : c.value("commands", json::array())) {
        if (cmd == "twist") has_twist = true;
        if (cmd == "twist") teleop.push_back(robot);
        if (cmd == "waypoints") waypoint.push_back(robot);
      }
      if (has_twist && (c.value("type", "") == "trot_gait" || c.value("type", "") == "policy"))
        teleop_vy = true;
      if (index >= 0 && index < sim.num_controllers()) {
        const Controller& ctl = sim.controller(index);
        // the control period: of the teleoperated controller, else of the first
        if (period == dt || has_twist)
          period = ctl.rate_hz() > 0 ? std::max(dt, std::round(1.0 / ctl.rate_hz() / dt) * dt) : dt;
        if (const JointTarget* joint_target = AsJointTarget(ctl))
          joint_controls.push_back(JointControl(robot, joint_target->command_joints()));
      }
    }
    if (sim.num_controllers() == 0) {
      json names = json::array(), lo = json::array(), hi = json::array(), value = json::array();
      for (const json& a : model_info_.value("actuators", json::array())) {
        if (!a.value("ctrl_limited", false)) continue;
        names.push_back(a["name"]);
        lo.push_back(a["ctrl_range"][0]);
        hi.push_back(a["ctrl_range"][1]);
        value.push_back(0.0);
      }
      if (!names.empty())
        joint_controls.push_back({{"kind", "ctrl"},
                                  {"robot", ""},
                                  {"names", names},
                                  {"min", lo},
                                  {"max", hi},
                                  {"value", value},
                                  {"unit", ""}});
    }
    control_period_sec_ = period;
    json colormap = json::array();
    for (int i = 0; i < 256; ++i) {
      const auto c = TurboColor(i / 255.0);
      colormap.push_back(fmt::format("#{:02x}{:02x}{:02x}", c[0], c[1], c[2]));
    }
    json presets = json::array();
    for (const std::string& n : BundledAdversityPresetNames()) presets.push_back(n);
    hello_ = {{"type", "viewer_hello"},
              {"protocol", kCommandProtocolVersion},
              // the file's name only: no client learns the server's folders
              {"world", std::filesystem::path(world_.file).filename().string()},
              {"model", model_info_},
              {"timestep_sec", dt},
              {"control_period_sec", period},
              {"presets", presets},
              {"preset", PresetForClient(world_.adversity)},
              {"effect_sliders", EffectSliders()},
              {"joint_controls", joint_controls},
              {"teleop_robots", teleop},
              {"teleop_vy", teleop_vy},
              {"waypoint_robots", waypoint},
              {"record_available", true},
              {"colormap", colormap}};
    // with the bodies' poses as the run starts: a page of a run paused at its start gets no
    // state message before the first step, and places its bodies and camera from these
    json scene = SceneJson(session_.scene());
    scene["X_WB"] = BodyPosesJson(sim.Snapshot(Simulation::SnapshotContent::kPoses));
    // a crowd's walkable map, drawn on the floor of the scene view (docs/npcs.md)
    if (session_.effects().npc_map()) scene["npc_map"] = nlohmann::json::parse(NpcMapJson(session_));
    scene_ = std::make_shared<const std::string>(scene.dump());
    for (const json& j : model_info_.value("joints", json::array())) {
      const std::string type = j.value("type", "");
      if (type == "hinge" || type == "slide")
        joint_signals_.emplace_back("joint/" + j.value("name", ""), j.value("qpos_adr", 0));
    }
    for (const CameraSpec& c : session_.scene().cameras) intrinsics_[c.name] = c.intrinsics;
    // the robot each body belongs to (composed names "<robot>/<body>"), for the robots'
    // contact forces
    const std::vector<std::string>& bodies = sim.model_info().body_names;
    body_robot_.assign(bodies.size(), -1);
    for (const ModelConfig& m : world_.models) {
      if (!m.is_robot) continue;
      const int r = static_cast<int>(robot_names_.size());
      robot_names_.push_back(m.name);
      for (size_t b = 0; b < bodies.size(); ++b)
        if (bodies[b].rfind(m.name + "/", 0) == 0) body_robot_[b] = r;
    }
  }

  json JointControl(const std::string& robot, const std::vector<std::string>& joints) const {
    json names = json::array(), lo = json::array(), hi = json::array(), value = json::array();
    for (const std::string& name : joints) {
      double a = -3.14159, b = 3.14159, q0 = 0;
      for (const json& j : model_info_.value("joints", json::array())) {
        if (j.value("name", "") != name) continue;
        if (j.value("limited", false)) {
          a = j["range"][0];
          b = j["range"][1];
        }
      }
      names.push_back(name);
      lo.push_back(a);
      hi.push_back(b);
      value.push_back(std::clamp(q0, a, b));
    }
    return {{"kind", "joint_targets"}, {"robot", robot}, {"names", names}, {"min", lo}, {"max", hi},
            {"value", value},          {"unit", "rad"}};
  }

  // the adversity sliders: block, key, range and the value that removes the block ("off");
  // their values come with every status message (AdversityJson)
  json EffectSliders() const {
    auto slider = [](const char* block, const char* key, const char* label, const char* unit,
                     double min, double max, double step, double off) {
      return json{{"block", block}, {"key", key}, {"label", label},
                  {"unit", unit},   {"min", min}, {"max", max},
                  {"step", step},   {"off", off}, {"integer", false}};
    };
    json s = json::array();
    s.push_back(slider("fog", "mor_m", "fog MOR", "m", 2, 300, 1, 300));
    s.push_back(slider("smoke", "sigma_t_per_m", "smoke extinction", "1/m", 0, 3, 0.05, 0));
    s.push_back(slider("rain", "rate_mm_h", "rain rate", "mm/h", 0, 50, 0.5, 0));
    s.push_back(slider("snow", "rate_mm_h", "snow rate", "mm/h", 0, 20, 0.5, 0));
    s.push_back(slider("lights", "scale", "light scale", "", 0, 1, 0.01, 1));
    // a run cannot add bodies to its loaded model: the run has the NPC bodies it started with
    // (a live run also parks bodies for the bundled presets' NPCs: live/live_effects.h)
    const int npc_bodies = std::max(
        0, static_cast<int>(session_.effects().agent_bodies().size() - world_.agents.size()));
    json npcs = slider("npcs", "people", "NPC count", "", 0, npc_bodies, 1, 0);
    npcs["integer"] = true;
    s.push_back(npcs);
    return s;
  }

  // the adversity the run is in (as requested: a queued change applies at the next step
  // boundary): the preset's name, whether a block was changed since, and each slider's value
  // ("<block>.<key>"; null = the block is off)
  json AdversityJson() const {
    RequestedAdversity r;
    if (LiveControl* live = dispatcher_.live()) {
      r = live->effects().requested_adversity();
    } else {
      r.preset = session_.effects().preset();
      if (r.preset && !r.preset->name.empty()) r.name = r.preset->name;
    }
    const AdversityPreset p = r.preset.value_or(AdversityPreset{});
    auto opt = [](const std::optional<double>& v) { return v ? json(*v) : json(nullptr); };
    json values = {{"fog.mor_m", opt(p.fog_mor_m)},
                   {"smoke.sigma_t_per_m", opt(p.smoke_sigma_t_per_m)},
                   {"rain.rate_mm_h", opt(p.rain_rate_mm_h)},
                   {"snow.rate_mm_h", opt(p.snow_rate_mm_h)},
                   {"lights.scale", p.light_scale},
                   {"npcs.people", p.npc_people}};
    return {{"preset", PresetForClient(r.name)},
            {"edited", r.edited},
            {"changes", r.changes},
            {"values", values}};
  }

  // ---- server handlers (server thread) ----
  std::vector<WebMessage> OnOpen(int client) {
    ++clients_;
    json hello = hello_;
    hello["paused"] = control_.paused();
    hello["realtime_factor"] = control_.realtime_factor();
    std::vector<WebMessage> out = {WebMessage::Text(hello.dump()), WebMessage{scene_, false},
                                   WebMessage::Text(StatusJson(json::object()).dump())};
    std::lock_guard<std::mutex> lock(mu_);
    if (last_state_) out.push_back(WebMessage{last_state_, false});
    return out;
  }

  void OnClose(int client) {
    --clients_;
    std::lock_guard<std::mutex> lock(sub_mu_);
    subscriptions_.erase(client);
    UpdateWanted();
  }

  std::string OnMessage(int client, std::string_view text) {
    json request;
    try {
      request = json::parse(text);
    } catch (const json::exception& e) {
      return CommandErrorReply(nullptr, nullptr, command_code::kMalformed, "",
                               std::string("not JSON: ") + e.what())
          .dump();
    }
    if (!request.is_object())
      return CommandErrorReply(nullptr, nullptr, command_code::kMalformed, "",
                               "expected a JSON object {\"cmd\": NAME, ...}")
          .dump();
    if (request.contains("cmd") && request["cmd"] == "subscribe") return Subscribe(client, request);
    const std::string cmd =
        request.value("cmd", json()).is_string() ? request["cmd"].get<std::string>() : "";
    dispatcher_.Dispatch(request, [this, client, cmd](json reply) {
      server_->Send(client, WebMessage::Text(reply.dump()));
      // the run's state changed at a boundary: every page learns it at once
      if (reply.value("ok", false) &&
          (cmd == "pause" || cmd == "resume" || cmd == "step" || cmd == "reset" ||
           cmd == "set_realtime_factor" || cmd == "set_adversity" || cmd == "set_effect")) {
        json status = json::object();
        if (reply.contains("step") && cmd != "set_adversity" && cmd != "set_effect")
          status["step"] = reply["step"];
        if (reply.contains("applies_from_step"))
          status["applies_from_step"] = reply["applies_from_step"];
        if (reply.contains("time_sec")) status["time_sec"] = reply["time_sec"];
        PublishStatus(status);
      }
    });
    return "";
  }

  // {"cmd": "subscribe", "id"?, "streams": ["camera/<camera>/<rgb|depth|segmentation>", ...]}
  std::string Subscribe(int client, const json& request) {
    const json* id = request.contains("id") ? &request["id"] : nullptr;
    const json cmd = "subscribe";
    for (const auto& [key, value] : request.items())
      if (key != "cmd" && key != "id" && key != "streams")
        return CommandErrorReply(cmd, id, command_code::kUnknownField, key,
                                 "subscribe takes only `streams`")
            .dump();
    if (!request.contains("streams"))
      return CommandErrorReply(cmd, id, command_code::kMissingField, "streams",
                               "expected a list of camera/<camera>/<rgb|depth|segmentation>")
          .dump();
    const json& streams = request["streams"];
    if (!streams.is_array() || streams.size() > 64)
      return CommandErrorReply(cmd, id, command_code::kBadField, "streams",
                               "expected a list of at most 64 stream names")
          .dump();
    std::set<std::string> wanted;
    for (size_t i = 0; i < streams.size(); ++i) {
      const std::string field = fmt::format("streams[{}]", i);
      if (!streams[i].is_string())
        return CommandErrorReply(cmd, id, command_code::kBadField, field, "expected a string")
            .dump();
      const std::string s = streams[i];
      const size_t slash = s.rfind('/');
      const std::string camera =
          s.rfind("camera/", 0) == 0 && slash > 7 ? s.substr(7, slash - 7) : "";
      const std::string kind = slash == std::string::npos ? "" : s.substr(slash + 1);
      const CameraSpec* spec = nullptr;
      for (const CameraSpec& c : session_.scene().cameras)
        if (c.name == camera) spec = &c;
      const bool kind_ok = spec && ((kind == "rgb" && spec->outputs[ImageKind::kRgb]) ||
                                    (kind == "depth" && spec->outputs[ImageKind::kDepth]) ||
                                    (kind == "segmentation" && spec->outputs[ImageKind::kRgb] &&
                                     spec->outputs[ImageKind::kSegmentation]));
      if (!kind_ok)
        return CommandErrorReply(
                   cmd, id, command_code::kBadField, field,
                   "'" + SanitizeForMessage(s, 200) +
                       "' is not a stream of this run; expected camera/<camera>/<kind> with a "
                       "camera of model_info.cameras and a kind it outputs (rgb, depth, "
                       "segmentation: needs rgb and segmentation)")
            .dump();
      wanted.insert(s);
    }
    {
      std::lock_guard<std::mutex> lock(sub_mu_);
      subscriptions_[client] = wanted;
      UpdateWanted();
    }
    {
      // the newest frame of each camera now, at once (a paused run renders no new one)
      std::lock_guard<std::mutex> lock(mu_);
      for (const std::string& st : wanted) {
        const std::string camera = st.substr(7, st.rfind('/') - 7);
        auto it = last_frames_.find(camera);
        if (it != last_frames_.end()) pending_frames_[camera] = it->second;
      }
      cv_.notify_one();
    }
    json reply = {{"ok", true}, {"cmd", "subscribe"}, {"streams", wanted}};
    if (id) reply["id"] = *id;
    return reply.dump();
  }

  // sub_mu_ held
  void UpdateWanted() {
    wanted_cameras_.clear();
    for (const auto& [client, streams] : subscriptions_)
      for (const std::string& s : streams) {
        wanted_cameras_.insert(s.substr(7, s.rfind('/') - 7));
      }
  }

  // the state the page's controls show, in full (docs/viewer.md "status"): run state, real-
  // time factor and adversity, with `fields` (step, time_sec of a boundary) added
  json StatusJson(json fields) const {
    fields["type"] = "status";
    fields["paused"] = control_.paused();
    fields["ended"] = ended_.load();
    fields["realtime_factor"] = control_.realtime_factor();
    fields["adversity"] = AdversityJson();
    return fields;
  }

  // every page learns the new state at once; the adversity changes it shows are noted, so
  // that a change from another client (ZeroMQ) is published once at the next step (Wants)
  void PublishStatus(json fields) {
    json status = StatusJson(std::move(fields));
    const int64_t changes = status["adversity"]["changes"];
    int64_t seen = published_changes_.load();
    while (seen < changes && !published_changes_.compare_exchange_weak(seen, changes)) {
    }
    server_->Publish("status", WebMessage::Text(status.dump()));
  }

  // ---- encoder thread ----
  void StopEncoder() {
    {
      std::lock_guard<std::mutex> lock(mu_);
      stop_ = true;
      cv_.notify_all();
    }
    if (encoder_.joinable()) encoder_.join();
  }

  void EncoderLoop() {
    JpegEncoder jpeg;
    for (;;) {
      std::shared_ptr<const WorldSnapshot> state;
      std::map<std::string, std::shared_ptr<const CameraFrame>> frames;
      {
        std::unique_lock<std::mutex> lock(mu_);
        cv_.wait(lock, [this] { return stop_ || pending_state_ || !pending_frames_.empty(); });
        if (stop_) return;
        state = std::move(pending_state_);
        pending_state_.reset();
        frames.swap(pending_frames_);
      }
      try {
        if (state) {
          PublishState(*state);
          latest_state_ = state;
        }
        for (const auto& [camera, frame] : frames) PublishFrame(*frame, &jpeg);
        PublishLidar(latest_state_);
      } catch (const std::exception& e) {
        spdlog::warn("viewer: {}", e.what());
      }
    }
  }

  void PublishState(const WorldSnapshot& s) {
    json signals = json::object();
    for (const auto& [name, adr] : joint_signals_)
      if (adr < static_cast<int>(s.qpos.size())) signals[name] = s.qpos[adr];
    // every contact's normal force (contact frame x, MuJoCo mj_contactForce), summed: all
    // contacts (resting furniture included), and per robot those between one of its bodies
    // and anything else (its own self contacts are internal forces)
    double normal = 0;
    std::vector<double> robot_normal(robot_names_.size(), 0.0);
    auto robot_of = [this](int body) {
      return body >= 0 && body < static_cast<int>(body_robot_.size()) ? body_robot_[body] : -1;
    };
    for (const WorldSnapshot::Contact& c : s.contacts) {
      normal += c.force_N.x();
      const int r1 = robot_of(c.body1), r2 = robot_of(c.body2);
      if (r1 == r2) continue;
      if (r1 >= 0) robot_normal[r1] += c.force_N.x();
      if (r2 >= 0) robot_normal[r2] += c.force_N.x();
    }
    signals["contacts/normal_force_N"] = normal;
    for (size_t r = 0; r < robot_names_.size(); ++r)
      signals["contacts/" + robot_names_[r] + "/normal_force_N"] = robot_normal[r];
    signals["contacts/count"] = s.contacts.size();
    for (size_t i = 0; i < s.tracking_error.size(); ++i)
      signals[fmt::format("control/tracking_error[{}]", i)] = s.tracking_error[i];
    {
      std::lock_guard<std::mutex> lock(sig_mu_);
      for (const auto& [k, v] : sensor_signals_.items()) signals[k] = v;
    }
    const json state = {{"type", "state"},
                        {"time_sec", s.time_sec},
                        {"step", s.step},
                        {"paused", control_.paused()},
                        {"ended", ended_.load()},
                        {"realtime_factor", control_.realtime_factor()},
                        {"steps_per_sec", steps_.Rate()},
                        {"render_fps", rendered_.Rate()},
                        {"X_WB", BodyPosesJson(s)},
                        {"cameras", CameraPosesJson(session_.scene(), s)},
                        {"signals", signals}};
    auto msg = std::make_shared<const std::string>(state.dump());
    {
      std::lock_guard<std::mutex> lock(mu_);
      last_state_ = msg;
    }
    server_->Publish("state", WebMessage{msg, false});
  }

  void PublishFrame(const CameraFrame& f, JpegEncoder* jpeg) {
    std::map<std::string, std::vector<int>> streams;  // stream -> its clients
    {
      std::lock_guard<std::mutex> lock(sub_mu_);
      for (const auto& [client, subscribed] : subscriptions_)
        for (const std::string& st : subscribed) streams[st].push_back(client);
    }
    const CameraIntrinsics& K = intrinsics_[f.camera];
    for (const char* kind : {"rgb", "depth", "segmentation"}) {
      const std::string stream = "camera/" + f.camera + "/" + kind;
      if (!streams.count(stream) || !FrameHas(f, kind)) continue;
      json header = {{"type", "frame"},
                     {"stream", stream},
                     {"camera", f.camera},
                     {"kind", kind},
                     {"time_sec", f.time_sec},
                     {"step", f.step},
                     {"index", f.index},
                     {"fx", K.fx},
                     {"fy", K.fy},
                     {"cx", K.cx},
                     {"cy", K.cy},
                     {"X_WO", PoseJson(f.X_WO)}};
      ImageU8 image;
      const ImageU8* src = &f.rgb;
      if (std::string_view(kind) == "depth") {
        DepthColorMap m = ColorizeDepth(f.depth_m);
        header["near_m"] = m.near_m;
        header["far_m"] = m.far_m;
        image = std::move(m.image);
        src = &image;
      } else if (std::string_view(kind) == "segmentation") {
        image = SegmentationOverlay(f.rgb, f.geom_id);
        src = &image;
      }
      header["width"] = src->width;
      header["height"] = src->height;
      auto [it, added] = quality_.try_emplace(stream, options_.jpeg);
      AdaptiveJpegQuality& q = it->second;
      header["quality"] = q.quality();
      const std::string bytes = jpeg->Encode(*src, q.quality());
      // frames of any stream replaced unsent since this stream's last frame: a client lags
      const int64_t replaced = server_->stats().messages_replaced;
      const Clock::time_point now = Clock::now();
      auto& [last_time, last_replaced] = stream_clock_[stream];
      q.Update(bytes.size(), added ? 0.0 : Seconds(now - last_time),
               added ? 0 : replaced - last_replaced);
      last_time = now;
      last_replaced = replaced;
      server_->PublishTo(streams[stream], stream,
                         WebMessage::Binary(PackFrameMessage(header, bytes)));
    }
  }

  // the sensor's pose in the world at `s` (body or site of the world file's entry)
  std::optional<Pose> SensorPose(const std::string& name, const WorldSnapshot& s) const {
    const ModelInfo& mi = session_.sim().model_info();
    for (const SensorConfig& c : world_.sensors) {
      if (c.name != name) continue;
      Pose X_WA = Pose::Identity();
      if (!c.site.empty()) {
        const int site = mi.Find(ModelObject::kSite, c.site);
        if (site < 0) return std::nullopt;
        const int body = mi.site_body[site];
        if (body >= static_cast<int>(s.X_WB.size())) return std::nullopt;
        X_WA = s.X_WB[body] * mi.site_X_BS[site];
      } else if (c.body != "world" && !c.body.empty()) {
        const int body = mi.Find(ModelObject::kBody, c.body);
        if (body < 0 || body >= static_cast<int>(s.X_WB.size())) return std::nullopt;
        X_WA = s.X_WB[body];
      }
      return X_WA * c.X_AS();
    }
    return std::nullopt;
  }

  // each completed scan's points in the world frame (at the sensor's pose of the latest state;
  // a spinning scan's own motion is not undone: it is a picture, not a measurement)
  void PublishLidar(const std::shared_ptr<const WorldSnapshot>& latest) {
    std::map<std::string, SensorSample> scans;
    {
      std::lock_guard<std::mutex> lock(sig_mu_);
      scans.swap(pending_lidar_);
    }
    if (!latest) return;
    for (const auto& [name, s] : scans) {
      const std::optional<Pose> X_WS = SensorPose(name, *latest);
      if (!X_WS) continue;
      json pts = json::array();
      const size_t n = s.scan->points.size();
      const size_t stride = std::max<size_t>(1, n / 20000);  // at most ~20k points per scan
      for (size_t i = 0; i < n; i += stride) {
        const LidarPoint& p = s.scan->points[i];
        const Eigen::Vector3d w = *X_WS * Eigen::Vector3d(p.x, p.y, p.z);
        for (int k = 0; k < 3; ++k) pts.push_back(std::round(w[k] * 1e3) / 1e3);
      }
      json m = {{"type", std::string(SensorKindName(SensorKind::kLidar))},
                {"sensor", name},
                {"time_sec", s.time_sec},
                {"points", std::move(pts)}};
      server_->Publish("lidar/" + name, WebMessage::Text(m.dump()));
    }
  }

  Session& session_;
  const WorldConfig& world_;
  CommandDispatcher& dispatcher_;
  RunControl& control_;
  const json& model_info_;
  ViewerOptions options_;

  json hello_;
  std::shared_ptr<const std::string> scene_;
  double control_period_sec_ = 0;
  std::vector<std::pair<std::string, int>> joint_signals_;
  std::vector<std::string> robot_names_;  // the world's robots
  std::vector<int> body_robot_;           // body -> index in robot_names_, -1 for none
  std::map<std::string, CameraIntrinsics> intrinsics_;
  std::unique_ptr<WebServer> server_;
  std::atomic<int> clients_{0};
  std::atomic<bool> ended_{false};
  std::atomic<int64_t> published_changes_{0};  // adversity changes the pages were told of

  // loop thread
  Clock::time_point last_state_wall_ = Clock::now();
  int64_t state_step_ = -1;
  RateMeter steps_, rendered_;

  // subscriptions (server thread writes, render/encoder threads read)
  std::mutex sub_mu_;
  std::map<int, std::set<std::string>> subscriptions_;
  std::set<std::string> wanted_cameras_;

  // sensor signals and scans (sensor thread writes)
  std::mutex sig_mu_;
  json sensor_signals_ = json::object();
  std::map<std::string, SensorSample> pending_lidar_;

  // encoder thread: latest snapshot and latest frame per camera
  std::mutex mu_;
  std::condition_variable cv_;
  bool stop_ = false;
  std::shared_ptr<const WorldSnapshot> pending_state_;
  std::map<std::string, std::shared_ptr<const CameraFrame>> pending_frames_;
  std::map<std::string, std::shared_ptr<const CameraFrame>> last_frames_;
  std::shared_ptr<const std::string> last_state_;
  std::thread encoder_;
  std::shared_ptr<const WorldSnapshot> latest_state_;  // encoder thread
  std::map<std::string, AdaptiveJpegQuality> quality_;
  std::map<std::string, std::pair<Clock::time_point, int64_t>> stream_clock_;
};

}  // namespace

RunBridgeFactory MakeViewerBridgeFactory(ViewerOptions options) {
  options.ValidateOrThrow();
  return [options](const RunBridgeContext& ctx) -> std::unique_ptr<RunBridge> {
    return std::make_unique<ViewerBridge>(ctx, options);
  };
}

}  // namespace penumbra
