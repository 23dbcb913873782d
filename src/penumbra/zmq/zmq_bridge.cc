#include "penumbra/zmq/zmq_bridge.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>
#include <sys/eventfd.h>
#include <unistd.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <deque>
#include <map>
#include <mutex>
#include <optional>
#include <thread>
#include <unordered_set>
#include <zmq.hpp>

#include "penumbra/command/command_dispatcher.h"
#include "penumbra/command/run_control.h"
#include "penumbra/core/error.h"
#include "penumbra/zmq/msgpack_json.h"

namespace penumbra {
namespace {

using json = nlohmann::json;

constexpr int64_t kHardMessageLimit = 64ll << 20;  // ZMQ_MAXMSGSIZE: peers above it are dropped
constexpr size_t kMaxRequestFrames = 4;            // frames kept of one request (rest dropped)

// subscriptions (docs/zmq-protocol.md, "Limits"). XPUB passes each distinct prefix up once,
// however many subscribers share it, so these bound what the bridge keeps and checks:
// prefixes beyond kMaxSubscriptions distinct ones, or longer than the prefix cap (256 bytes,
// or the run's longest topic if longer: no topic needs a longer prefix), are dropped and
// logged. a subscription message above twice the cap makes ZeroMQ drop that subscriber
// (ZMQ_MAXMSGSIZE), which also bounds what ZeroMQ's own subscription tree holds per prefix.
// the number of prefixes in that tree is not bounded: ZMQ_XPUB_MANUAL still records every
// subscription of every subscriber (measured the same memory), a subscription message names
// no subscriber (Peer-Address is the IP only), and XPUB cannot disconnect one subscriber.
constexpr size_t kMaxSubscriptions = 1024;
constexpr size_t kMinPrefixCap = 256;
constexpr int kSubscriptionsPerTurn = 256;  // handled per turn of the publish thread
constexpr int kLoggedDrops = 10;            // drops logged one by one, then only counted

// shutdown: after the run ended, requests are answered with `stopping` until none came for
// kDrainQuiet (or kDrainMax after the bridge was closed), then the sockets close
constexpr auto kDrainQuiet = std::chrono::milliseconds(300);
constexpr auto kDrainMax = std::chrono::seconds(3);

json PoseJson(const Pose& X) {
  const Eigen::Quaterniond q(X.linear());
  return {{"xyz", {X.translation().x(), X.translation().y(), X.translation().z()}},
          {"qwxyz", {q.w(), q.x(), q.y(), q.z()}}};
}

json Vec3(const Eigen::Vector3d& v) { return {v.x(), v.y(), v.z()}; }

// a zero-copy ZeroMQ message over a buffer owned by `owner` (kept alive until ZeroMQ is done)
template <typename T>
zmq::message_t SharedMessage(const void* data, size_t size, std::shared_ptr<const T> owner) {
  auto* hint = new std::shared_ptr<const T>(std::move(owner));
  return zmq::message_t(
      const_cast<void*>(data), size,
      [](void*, void* h) { delete static_cast<std::shared_ptr<const T>*>(h); }, hint);
}

// splits "tcp://HOST:PORT" into host and port; false for anything else
bool SplitTcp(const std::string& e, std::string* host, int* port) {
  if (e.rfind("tcp://", 0) != 0) return false;
  const size_t colon = e.rfind(':');
  if (colon == std::string::npos || colon < 6) return false;
  *host = e.substr(6, colon - 6);
  const std::string p = e.substr(colon + 1);
  if (host->empty() || p.empty() || p.size() > 5 ||
      !std::all_of(p.begin(), p.end(), [](char c) { return c >= '0' && c <= '9'; }))
    return false;
  *port = std::stoi(p);
  return *port >= 1 && *port <= 65535;
}

class ZmqBridge final : public RunBridge {
 public:
  ZmqBridge(const RunBridgeContext& context, ZmqBridgeOptions options);
  ~ZmqBridge() override;

  void OnStart(const LoopStart& start) override { report_error_ = start.report_error; }
  SnapshotContent Wants(int64_t step, double time_sec) override;
  void OnSnapshot(const std::shared_ptr<const WorldSnapshot>& snapshot) override;
  void OnFinish(const LoopFinish& finish) override;
  void OnCameraFrame(const std::shared_ptr<const CameraFrame>& frame) override;
  void OnSensorSample(const SensorSample& sample) override;

 private:
  struct Outgoing {
    std::vector<zmq::message_t> frames;
    uint64_t after_publication = 0;  // a reply: sent once publications up to this one are
  };

  void CommandLoop();
  void PublishLoop();
  void HandleRequest(std::vector<zmq::message_t>& frames, size_t total_frames);
  // whether a received request is a `stop` that will be carried out (cmd and id only)
  bool IsStopRequest(const std::vector<zmq::message_t>& frames, size_t total_frames) const;
  void HandleSubscription(const zmq::message_t& m);
  // queues a reply; `after_publications`: not sent before every publication queued so far
  // (a `step` reply follows the messages of its steps)
  void SendReply(const std::vector<std::string>& envelope, json reply,
                 bool after_publications = false);
  void Publish(const std::string& topic, const json& header, zmq::message_t payload);
  bool Subscribed(const std::string& topic) const;
  static void Wake(int fd);
  static void Send(zmq::socket_t& s, Outgoing& o, const char* what);
  void Shutdown();
  void PublishImage(const std::string& topic, const CameraFrame& f, const char* encoding, int width,
                    int height, int bytes_per_pixel, zmq::message_t payload);

  RunControl& control_;
  CommandDispatcher& dispatcher_;
  const Simulation& sim_;
  ZmqBridgeOptions options_;
  std::string endpoint_, pub_endpoint_;
  json topics_;
  std::map<std::string, json> intrinsics_;  // camera name -> {fx, fy, cx, cy}
  std::vector<std::string> body_names_;
  std::vector<int> state_joints_;  // hinge and slide joints (joint_states)
  std::function<void(std::exception_ptr)> report_error_;

  zmq::context_t context_;
  zmq::socket_t router_, xpub_;
  // the command thread owns router_, the publish thread xpub_: ZeroMQ's own work on
  // subscriptions (e.g. thousands removed when their subscriber leaves) never delays commands
  int cmd_wake_fd_ = -1, pub_wake_fd_ = -1;
  std::thread cmd_io_, pub_io_;

  // subscriptions (publish thread writes, everyone reads)
  mutable std::mutex sub_mu_;
  std::unordered_set<std::string> prefixes_;
  size_t prefix_cap_ = kMinPrefixCap;
  int64_t dropped_long_ = 0, dropped_over_cap_ = 0;

  // the outgoing queues
  std::mutex out_mu_;
  std::condition_variable out_cv_;
  std::deque<Outgoing> publications_, replies_;
  uint64_t queued_publications_ = 0;  // publications queued so far (their sequence)
  std::atomic<uint64_t> sent_publications_{0};
  int pending_publications_ = 0;
  std::map<std::string, int64_t> published_;  // messages queued per topic
  int64_t dropped_ = 0;
  bool closing_ = false;
  std::atomic<bool> stopping_{false};  // the run ended: requests get a `stopping` error
  std::atomic<bool> stop_io_{false};
  std::atomic<bool> publish_done_{false};

  // loop thread: state topic schedule
  int64_t next_state_ = 0;
  int64_t state_step_ = -1;
};

ZmqBridge::ZmqBridge(const RunBridgeContext& context, ZmqBridgeOptions options)
    : control_(context.control),
      dispatcher_(context.dispatcher),
      sim_(context.session.sim()),
      options_(std::move(options)),
      context_(1),
      router_(context_, zmq::socket_type::router),
      xpub_(context_, zmq::socket_type::xpub) {
  options_.ValidateOrThrow();
  std::tie(endpoint_, pub_endpoint_) = options_.ResolveEndpoints();
  for (const json& c : context.model_info.at("cameras"))
    intrinsics_[c.at("name").get<std::string>()] = {
        {"fx", c.at("fx")}, {"fy", c.at("fy")}, {"cx", c.at("cx")}, {"cy", c.at("cy")}};
  const ModelInfo& mi = sim_.model_info();
  body_names_ = mi.body_names;
  for (size_t j = 0; j < mi.joints.size(); ++j)
    if (mi.joints[j].type == JointInfo::Type::kHinge ||
        mi.joints[j].type == JointInfo::Type::kSlide)
      state_joints_.push_back(static_cast<int>(j));

  // the topics this run can publish (hello, model_info)
  topics_ = json::array();
  for (const json& c : context.model_info.at("cameras")) {
    const std::string base = "camera/" + c.at("name").get<std::string>() + "/";
    for (const json& o : c.at("outputs")) {
      const std::string out = o.get<std::string>();
      topics_.push_back(base + out);
      if (out == ImageKindName(ImageKind::kDepth)) topics_.push_back(base + "depth_mm");
    }
  }
  for (const SensorConfig& s : context.world.sensors) {
    if (s.kind() == SensorKind::kImu) topics_.push_back("imu/" + s.name);
    if (s.kind() == SensorKind::kLidar) topics_.push_back("lidar/" + s.name);
    if (s.kind() == SensorKind::kMujoco) topics_.push_back("sensor/" + s.name);
  }
  for (const char* t : {"clock", "joint_states", "ground_truth/poses", "contacts", "sync", "end"})
    topics_.push_back(t);
  for (const json& t : topics_) prefix_cap_ = std::max(prefix_cap_, t.get<std::string>().size());

  router_.set(zmq::sockopt::linger, 1000);
  router_.set(zmq::sockopt::maxmsgsize, kHardMessageLimit);
  router_.set(zmq::sockopt::sndhwm, 10000);
  xpub_.set(zmq::sockopt::linger, 1000);
  xpub_.set(zmq::sockopt::sndhwm, options_.hwm);
  xpub_.set(zmq::sockopt::maxmsgsize, static_cast<int64_t>(1 + 2 * prefix_cap_));
  try {
    router_.bind(endpoint_);
  } catch (const zmq::error_t& e) {
    throw Error(
        fmt::format("cannot bind the ZeroMQ command socket to {}: {}", endpoint_, e.what()));
  }
  try {
    xpub_.bind(pub_endpoint_);
  } catch (const zmq::error_t& e) {
    throw Error(
        fmt::format("cannot bind the ZeroMQ publish socket to {}: {}", pub_endpoint_, e.what()));
  }
  cmd_wake_fd_ = eventfd(0, EFD_NONBLOCK | EFD_CLOEXEC);
  pub_wake_fd_ = eventfd(0, EFD_NONBLOCK | EFD_CLOEXEC);
  if (cmd_wake_fd_ < 0 || pub_wake_fd_ < 0) {
    if (cmd_wake_fd_ >= 0) close(cmd_wake_fd_);
    if (pub_wake_fd_ >= 0) close(pub_wake_fd_);
    throw Error("eventfd failed for the ZeroMQ bridge");
  }
  spdlog::info("ZeroMQ: commands on {}, sensors published on {} (docs/zmq-protocol.md){}",
               endpoint_, pub_endpoint_,
               control_.paused() ? "; lockstep: waiting for `step` requests" : "");
  pub_io_ = std::thread([this] { PublishLoop(); });
  cmd_io_ = std::thread([this] { CommandLoop(); });
}

ZmqBridge::~ZmqBridge() {
  Shutdown();
  close(cmd_wake_fd_);
  close(pub_wake_fd_);
}

void ZmqBridge::Shutdown() {
  {
    std::lock_guard<std::mutex> lock(out_mu_);
    closing_ = true;
  }
  out_cv_.notify_all();
  stopping_.store(true);
  stop_io_.store(true);
  Wake(pub_wake_fd_);
  Wake(cmd_wake_fd_);
  if (pub_io_.joinable()) pub_io_.join();
  if (cmd_io_.joinable()) cmd_io_.join();
}

void ZmqBridge::Wake(int fd) {
  const uint64_t one = 1;
  const ssize_t n = write(fd, &one, sizeof(one));
  (void)n;
}

bool ZmqBridge::Subscribed(const std::string& topic) const {
  // a subscription is a prefix of the topic: at most prefix_cap_ + 1 lookups
  std::lock_guard<std::mutex> lock(sub_mu_);
  if (prefixes_.empty()) return false;
  const size_t n = std::min(topic.size(), prefix_cap_);
  for (size_t k = 0; k <= n; ++k)
    if (prefixes_.count(topic.substr(0, k)) > 0) return true;
  return false;
}

void ZmqBridge::HandleSubscription(const zmq::message_t& m) {
  if (m.size() == 0) return;
  const auto* b = static_cast<const char*>(m.data());
  if (b[0] != 0 && b[0] != 1) return;  // not a subscription message
  std::string prefix(b + 1, m.size() - 1);
  std::lock_guard<std::mutex> lock(sub_mu_);
  if (b[0] == 0) {
    prefixes_.erase(prefix);
    return;
  }
  // a printable excerpt for the log
  const auto shown = [&] {
    std::string e = prefix.substr(0, 40);
    for (char& c : e)
      if (c < 0x20 || c > 0x7e) c = '?';
    return e + (prefix.size() > 40 ? "..." : "");
  };
  if (prefix.size() > prefix_cap_) {
    if (++dropped_long_ <= kLoggedDrops)
      spdlog::warn(
          "ZeroMQ: dropped a subscription of {} bytes ('{}'): longer than {} bytes, "
          "the longest prefix any topic needs{}",
          prefix.size(), shown(), prefix_cap_,
          dropped_long_ == kLoggedDrops ? "; further drops are only counted" : "");
    return;
  }
  if (prefixes_.count(prefix) == 0 && prefixes_.size() >= kMaxSubscriptions) {
    if (++dropped_over_cap_ <= kLoggedDrops)
      spdlog::warn(
          "ZeroMQ: dropped the subscription '{}': {} distinct subscriptions are held, "
          "the limit{}",
          shown(), kMaxSubscriptions,
          dropped_over_cap_ == kLoggedDrops ? "; further drops are only counted" : "");
    return;
  }
  prefixes_.insert(std::move(prefix));
}

void ZmqBridge::Publish(const std::string& topic, const json& header, zmq::message_t payload) {
  Outgoing o;
  o.frames.emplace_back(topic.data(), topic.size());
  const std::string h = EncodeMsgpack(header);
  o.frames.emplace_back(h.data(), h.size());
  o.frames.push_back(std::move(payload));
  {
    std::unique_lock<std::mutex> lock(out_mu_);
    if (closing_) return;
    if (pending_publications_ >= options_.queue_capacity) {
      if (control_.paused()) {
        // lockstep: nothing is dropped; the producer waits for the I/O thread
        out_cv_.wait(lock,
                     [&] { return pending_publications_ < options_.queue_capacity || closing_; });
        if (closing_) return;
      } else {
        ++dropped_;
        return;
      }
    }
    ++pending_publications_;
    ++published_[topic];
    ++queued_publications_;
    publications_.push_back(std::move(o));
  }
  Wake(pub_wake_fd_);
}

void ZmqBridge::SendReply(const std::vector<std::string>& envelope, json reply,
                          bool after_publications) {
  Outgoing o;
  for (const std::string& e : envelope) o.frames.emplace_back(e.data(), e.size());
  const std::string body = EncodeMsgpack(reply);
  o.frames.emplace_back(body.data(), body.size());
  {
    std::lock_guard<std::mutex> lock(out_mu_);
    if (after_publications) o.after_publication = queued_publications_;
    replies_.push_back(std::move(o));
  }
  Wake(cmd_wake_fd_);
}

bool ZmqBridge::IsStopRequest(const std::vector<zmq::message_t>& frames,
                              size_t total_frames) const {
  size_t body = 1;
  if (body < frames.size() && frames[body].size() == 0) ++body;
  if (total_frames != body + 1 || body >= frames.size()) return false;
  const zmq::message_t& m = frames[body];
  if (static_cast<int64_t>(m.size()) > options_.max_request_bytes) return false;
  try {
    const json request = DecodeMsgpack(m.data(), m.size());
    if (!request.is_object() || request.value("cmd", json()) != "stop") return false;
    // a stop that will be carried out: no field but cmd and id
    for (const auto& [key, value] : request.items())
      if (key != "cmd" && key != "id") return false;
    return true;
  } catch (const std::exception&) {
    return false;
  }
}

void ZmqBridge::HandleRequest(std::vector<zmq::message_t>& frames, size_t total_frames) {
  if (frames.empty()) return;
  std::vector<std::string> envelope{frames[0].to_string()};
  size_t body = 1;
  if (body < frames.size() && frames[body].size() == 0) {
    envelope.emplace_back();
    ++body;
  }
  auto error = [&](const char* code, const std::string& message) {
    SendReply(envelope, ErrorReply(nullptr, nullptr, CommandError(code, "", message)));
  };
  const size_t parts = total_frames - body;
  if (parts != 1) {
    error(command_code::kMalformed,
          fmt::format("the request has {} frames after the envelope; expected one frame holding "
                      "one msgpack map",
                      parts));
    return;
  }
  const zmq::message_t& m = frames[body];
  if (static_cast<int64_t>(m.size()) > options_.max_request_bytes) {
    error(command_code::kTooLarge,
          fmt::format("the request has {} bytes; the limit is {} (--zmq-max-request)", m.size(),
                      options_.max_request_bytes));
    return;
  }
  json request;
  try {
    request = DecodeMsgpack(m.data(), m.size());
  } catch (const std::exception& e) {
    error(command_code::kMalformed, std::string("the request is not a msgpack map: ") + e.what());
    return;
  }
  const std::string cmd =
      request.is_object() && request.contains("cmd") && request["cmd"].is_string()
          ? request["cmd"].get<std::string>()
          : "";
  // the run has ended: nothing more is carried out, but every request gets its reply
  if (stopping_.load() || control_.ended()) {
    const json* id = request.is_object() && request.contains("id") ? &request["id"] : nullptr;
    SendReply(envelope,
              ErrorReply(cmd.empty() ? json(nullptr) : json(cmd), id,
                         CommandError(command_code::kStopping, "",
                                      "the run has ended and the server is shutting down; the "
                                      "command was not carried out")));
    return;
  }
  if (cmd == "sync") {
    const json* id = request.contains("id") ? &request["id"] : nullptr;
    try {
      RequestReader rd(request);
      const std::string token = rd.String("token");
      rd.CheckNoUnknown();
      if (Subscribed("sync"))
        Publish("sync",
                {{"stamp", control_.boundary_time_sec()},
                 {"sim_step", control_.boundary_step()},
                 {"frame_id", ""},
                 {"token", token}},
                zmq::message_t());
      json r = {{"ok", true}, {"cmd", "sync"}, {"token", token}};
      if (id) r["id"] = *id;
      SendReply(envelope, std::move(r), true);
    } catch (const CommandError& e) {
      SendReply(envelope, ErrorReply("sync", id, e));
    }
    return;
  }
  // the reply's transport fields: hello/model_info name the topics, step counts publications
  std::shared_ptr<std::map<std::string, int64_t>> baseline;
  if (cmd == "step") {
    std::lock_guard<std::mutex> lock(out_mu_);
    baseline = std::make_shared<std::map<std::string, int64_t>>(published_);
  }
  dispatcher_.Dispatch(request, [this, envelope, cmd, baseline](json reply) {
    if (reply.value("ok", false)) {
      if (cmd == "hello") {
        reply["pub_endpoint"] = pub_endpoint_;
        reply["max_request_bytes"] = options_.max_request_bytes;
        reply["topics"] = topics_;
        reply["commands"].push_back("sync");
      } else if (cmd == "model_info") {
        reply["topics"] = topics_;
      } else if (cmd == "step" && baseline) {
        json counts = json::object();
        std::lock_guard<std::mutex> lock(out_mu_);
        for (const auto& [topic, n] : published_) {
          auto it = baseline->find(topic);
          const int64_t d = n - (it == baseline->end() ? 0 : it->second);
          if (d > 0) counts[topic] = d;
        }
        reply["published"] = std::move(counts);
      }
    }
    SendReply(envelope, std::move(reply), cmd == "step");
  });
}

void ZmqBridge::Send(zmq::socket_t& s, Outgoing& o, const char* what) {
  try {
    for (size_t i = 0; i < o.frames.size(); ++i) {
      const zmq::send_flags f = i + 1 < o.frames.size()
                                    ? zmq::send_flags::sndmore | zmq::send_flags::dontwait
                                    : zmq::send_flags::dontwait;
      if (!s.send(o.frames[i], f)) break;
    }
  } catch (const zmq::error_t& e) {
    spdlog::warn("ZeroMQ: dropped a {}: {}", what, e.what());
  }
}

void ZmqBridge::CommandLoop() {
  using Clock = std::chrono::steady_clock;
  zmq::pollitem_t items[] = {{router_.handle(), 0, ZMQ_POLLIN, 0},
                             {nullptr, cmd_wake_fd_, ZMQ_POLLIN, 0}};
  std::deque<Outgoing> waiting;  // replies in order, the first maybe waiting for publications
  Clock::time_point last_request = Clock::now();
  std::optional<Clock::time_point> closed_at;
  for (;;) {
    const bool closing = stop_io_.load();
    if (closing && !closed_at) closed_at = Clock::now();
    try {
      zmq::poll(items, 2, std::chrono::milliseconds(closing ? 20 : 100));
      if (items[1].revents & ZMQ_POLLIN) {
        uint64_t n = 0;
        const ssize_t r = read(cmd_wake_fd_, &n, sizeof(n));
        (void)r;
      }
      // requests: the messages waiting now (at most 64), at most kMaxRequestFrames frames kept
      std::vector<std::pair<std::vector<zmq::message_t>, size_t>> batch;
      for (int budget = 0; budget < 64; ++budget) {
        zmq::message_t part;
        if (!router_.recv(part, zmq::recv_flags::dontwait)) break;
        last_request = Clock::now();
        std::vector<zmq::message_t> frames;
        size_t total = 1;
        frames.push_back(std::move(part));
        while (router_.get(zmq::sockopt::rcvmore)) {
          zmq::message_t more;
          if (!router_.recv(more, zmq::recv_flags::dontwait)) break;
          ++total;
          if (frames.size() < kMaxRequestFrames) frames.push_back(std::move(more));
        }
        batch.emplace_back(std::move(frames), total);
      }
      // a `stop` among them (from any peer) counts from now: a start_recording that arrived
      // with it is refused, not left with a step or two (ZeroMQ takes the peers in turn, so a
      // second socket's request sent just after the stop can come first)
      for (const auto& [frames, total] : batch)
        if (IsStopRequest(frames, total)) control_.NoteStopQueued();
      for (auto& [frames, total] : batch) HandleRequest(frames, total);
    } catch (const zmq::error_t& e) {
      if (e.num() == ETERM) return;
      spdlog::warn("ZeroMQ: {}", e.what());
    } catch (const std::exception& e) {
      spdlog::warn("ZeroMQ: {}", e.what());
    }
    // replies in order; a `step` reply once the publications before it are sent
    {
      std::lock_guard<std::mutex> lock(out_mu_);
      while (!replies_.empty()) {
        waiting.push_back(std::move(replies_.front()));
        replies_.pop_front();
      }
    }
    const bool published_all = publish_done_.load();
    while (!waiting.empty() &&
           (published_all || waiting.front().after_publication <= sent_publications_.load())) {
      Send(router_, waiting.front(), "reply");
      waiting.pop_front();
    }
    if (!closed_at) continue;
    // closing: answer (`stopping`) until the peers are quiet, then send what is left
    const Clock::time_point now = Clock::now();
    const Clock::time_point quiet_since = std::max(last_request, *closed_at);
    bool queued = false;
    {
      std::lock_guard<std::mutex> lock(out_mu_);
      queued = !replies_.empty();
    }
    if ((published_all && waiting.empty() && !queued && now - quiet_since >= kDrainQuiet) ||
        now - *closed_at >= kDrainMax) {
      for (Outgoing& o : waiting) Send(router_, o, "reply");
      return;
    }
  }
}

void ZmqBridge::PublishLoop() {
  zmq::pollitem_t items[] = {{xpub_.handle(), 0, ZMQ_POLLIN, 0},
                             {nullptr, pub_wake_fd_, ZMQ_POLLIN, 0}};
  std::deque<Outgoing> sending;
  for (;;) {
    try {
      zmq::poll(items, 2, std::chrono::milliseconds(100));
      if (items[1].revents & ZMQ_POLLIN) {
        uint64_t n = 0;
        const ssize_t r = read(pub_wake_fd_, &n, sizeof(n));
        (void)r;
      }
      // subscriptions: a bounded number per turn, so publications keep flowing
      for (int budget = 0; budget < kSubscriptionsPerTurn; ++budget) {
        zmq::message_t sub;
        if (!xpub_.recv(sub, zmq::recv_flags::dontwait)) break;
        HandleSubscription(sub);
      }
    } catch (const zmq::error_t& e) {
      if (e.num() == ETERM) break;
      spdlog::warn("ZeroMQ: {}", e.what());
    } catch (const std::exception& e) {
      spdlog::warn("ZeroMQ: {}", e.what());
    }
    // everything queued, in order
    uint64_t last = 0;
    {
      std::lock_guard<std::mutex> lock(out_mu_);
      sending.swap(publications_);
      pending_publications_ = 0;
      last = queued_publications_;
    }
    out_cv_.notify_all();
    for (Outgoing& o : sending) Send(xpub_, o, "publication");
    const bool sent_any = !sending.empty();
    sending.clear();
    sent_publications_.store(last);
    if (sent_any) Wake(cmd_wake_fd_);
    if (stop_io_.load()) {
      std::lock_guard<std::mutex> lock(out_mu_);
      if (publications_.empty()) break;
    }
  }
  publish_done_.store(true);
  Wake(cmd_wake_fd_);
}

SnapshotContent ZmqBridge::Wants(int64_t step, double time_sec) {
  state_step_ = -1;
  bool due = true;
  if (options_.state_hz > 0) {
    due = time_sec >= static_cast<double>(next_state_) / options_.state_hz - 1e-9;
    if (due)
      next_state_ = std::max(next_state_ + 1,
                             static_cast<int64_t>(std::floor(time_sec * options_.state_hz)) + 1);
  }
  if (!due) return SnapshotContent::kNone;
  SnapshotContent c = SnapshotContent::kNone;
  if (Subscribed("clock")) c = SnapshotContent::kState;
  if (Subscribed("joint_states") || Subscribed("ground_truth/poses") || Subscribed("contacts"))
    c = SnapshotContent::kFull;
  if (c != SnapshotContent::kNone) state_step_ = step;
  return c;
}

void ZmqBridge::OnSnapshot(const std::shared_ptr<const WorldSnapshot>& snapshot) {
  if (snapshot->step != state_step_) return;
  const WorldSnapshot& s = *snapshot;
  auto header = [&](const char* frame_id) {
    return json{{"stamp", s.time_sec}, {"sim_step", s.step}, {"frame_id", frame_id}};
  };
  if (Subscribed("clock")) Publish("clock", header(""), zmq::message_t());
  if (Subscribed("joint_states") && !s.qpos.empty()) {
    const ModelInfo& mi = sim_.model_info();
    json h = header("");
    json names = json::array(), pos = json::array(), vel = json::array(), eff = json::array();
    for (int j : state_joints_) {
      const JointInfo& jt = mi.joints[j];
      names.push_back(jt.name);
      pos.push_back(s.qpos[jt.qpos_adr]);
      vel.push_back(s.qvel[jt.dof_adr]);
      eff.push_back(static_cast<size_t>(jt.dof_adr) < s.qfrc_actuator.size()
                        ? s.qfrc_actuator[jt.dof_adr]
                        : 0.0);
    }
    h["name"] = std::move(names);
    h["position"] = std::move(pos);
    h["velocity"] = std::move(vel);
    h["effort"] = std::move(eff);
    Publish("joint_states", h, zmq::message_t());
  }
  if (Subscribed("ground_truth/poses") && !s.X_WB.empty()) {
    json h = header("world");
    json names = json::array(), xyz = json::array(), q = json::array(), ang = json::array(),
         lin = json::array();
    for (size_t b = 1; b < s.X_WB.size() && b < body_names_.size(); ++b) {
      names.push_back(body_names_[b]);
      const json p = PoseJson(s.X_WB[b]);
      xyz.push_back(p["xyz"]);
      q.push_back(p["qwxyz"]);
      const Eigen::Matrix<double, 6, 1> V =
          b < s.V_WB.size() ? s.V_WB[b] : Eigen::Matrix<double, 6, 1>::Zero();
      ang.push_back({V[0], V[1], V[2]});
      lin.push_back({V[3], V[4], V[5]});
    }
    h["name"] = std::move(names);
    h["xyz"] = std::move(xyz);
    h["qwxyz"] = std::move(q);
    h["angular"] = std::move(ang);
    h["linear"] = std::move(lin);
    Publish("ground_truth/poses", h, zmq::message_t());
  }
  if (Subscribed("contacts")) {
    json h = header("world");
    json list = json::array();
    for (const WorldSnapshot::Contact& c : s.contacts)
      list.push_back({{"geom1", c.geom1},
                      {"geom2", c.geom2},
                      {"body1", c.body1},
                      {"body2", c.body2},
                      {"p_W", Vec3(c.p_W)},
                      {"normal_W", Vec3(c.normal_W)},
                      {"distance_m", c.distance_m},
                      {"force_N", Vec3(c.force_N)}});
    h["contacts"] = std::move(list);
    Publish("contacts", h, zmq::message_t());
  }
}

void ZmqBridge::PublishImage(const std::string& topic, const CameraFrame& f, const char* encoding,
                             int width, int height, int bytes_per_pixel, zmq::message_t payload) {
  json h = {{"stamp", f.time_sec},   {"sim_step", f.step},      {"frame_id", f.camera + "/optical"},
            {"camera", f.camera},    {"index", f.index},        {"encoding", encoding},
            {"width", width},        {"height", height},        {"step", width * bytes_per_pixel},
            {"is_bigendian", false}, {"X_WO", PoseJson(f.X_WO)}};
  auto it = intrinsics_.find(f.camera);
  if (it != intrinsics_.end())
    for (auto& [k, v] : it->second.items()) h[k] = v;
  Publish(topic, h, std::move(payload));
}

void ZmqBridge::OnCameraFrame(const std::shared_ptr<const CameraFrame>& frame) {
  const CameraFrame& f = *frame;
  const std::string base = "camera/" + f.camera + "/";
  auto shared = [&](const auto& img) {
    using T = typename std::decay_t<decltype(img.data)>::value_type;
    return SharedMessage<CameraFrame>(img.data.data(), img.data.size() * sizeof(T), frame);
  };
  // one topic per image kind (scene/image_kind.h), named after it, in the table's order; its
  // ROS encoding follows from the pixel type and channels (rgb8, 32FC1, 32FC3, 32SC1)
  for (const ImageKindInfo& k : kImageKinds) {
    WithImage(f, k.kind, [&](const auto& img) {
      using T = typename std::decay_t<decltype(img.data)>::value_type;
      const std::string topic = base + std::string(k.name);
      if (img.empty() || !Subscribed(topic)) return;
      const std::string encoding =
          k.pixel == PixelType::kU8
              ? "rgb8"
              : (k.pixel == PixelType::kF32 ? "32FC" : "32SC") + std::to_string(k.channels);
      PublishImage(topic, f, encoding.c_str(), img.width, img.height,
                   static_cast<int>(sizeof(T)) * k.channels, shared(img));
    });
    // depth also as 16-bit millimetres
    if (k.kind == ImageKind::kDepth && !f.depth_m.empty() && Subscribed(base + "depth_mm")) {
      zmq::message_t mm(f.depth_m.data.size() * sizeof(uint16_t));
      auto* out = static_cast<uint16_t*>(mm.data());
      for (size_t i = 0; i < f.depth_m.data.size(); ++i) {
        const double d = f.depth_m.data[i];
        out[i] = !(d > 0) ? 0 : static_cast<uint16_t>(std::min(65535.0, std::round(d * 1000.0)));
      }
      PublishImage(base + "depth_mm", f, "16UC1", f.depth_m.width, f.depth_m.height, 2,
                   std::move(mm));
    }
  }
}

void ZmqBridge::OnSensorSample(const SensorSample& sample) {
  json h = {{"stamp", sample.time_sec},
            {"sim_step", sample.step},
            {"frame_id", sample.kind == SensorKind::kMujoco ? std::string("world") : sample.sensor},
            {"index", sample.index}};
  if (sample.kind == SensorKind::kImu) {
    const std::string topic = "imu/" + sample.sensor;
    if (!Subscribed(topic) || sample.values.size() != 6) return;
    h["accel"] = {sample.values[0], sample.values[1], sample.values[2]};
    h["gyro"] = {sample.values[3], sample.values[4], sample.values[5]};
    Publish(topic, h, zmq::message_t());
  } else if (sample.kind == SensorKind::kMujoco) {
    const std::string topic = "sensor/" + sample.sensor;
    if (!Subscribed(topic)) return;
    h["columns"] = sample.columns ? json(*sample.columns) : json::array();
    h["values"] = sample.values;
    Publish(topic, h, zmq::message_t());
  } else if (sample.kind == SensorKind::kLidar && sample.scan) {
    const std::string topic = "lidar/" + sample.sensor;
    if (!Subscribed(topic)) return;
    const auto& pts = sample.scan->points;
    zmq::message_t payload(pts.size() * 5 * sizeof(float));
    auto* out = static_cast<float*>(payload.data());
    for (size_t i = 0; i < pts.size(); ++i) {
      out[5 * i + 0] = pts[i].x;
      out[5 * i + 1] = pts[i].y;
      out[5 * i + 2] = pts[i].z;
      out[5 * i + 3] = pts[i].intensity;
      out[5 * i + 4] = pts[i].time;
    }
    h["count"] = pts.size();
    h["point_step"] = 20;
    h["fields"] = {"x", "y", "z", "intensity", "time"};
    h["rays"] = sample.scan->rays;
    Publish(topic, h, std::move(payload));
  }
}

void ZmqBridge::OnFinish(const LoopFinish& finish) {
  const char* reason = finish.reason == LoopEndReason::kError           ? "error"
                       : finish.reason == LoopEndReason::kStopRequested ? "stopped"
                                                                        : "end_time";
  int64_t dropped = 0;
  {
    std::lock_guard<std::mutex> lock(out_mu_);
    dropped = dropped_;
  }
  if (dropped > 0)
    spdlog::warn("ZeroMQ: {} publications dropped (outgoing queue full while running free)",
                 dropped);
  {
    std::lock_guard<std::mutex> lock(sub_mu_);
    if (dropped_long_ + dropped_over_cap_ > 0)
      spdlog::warn(
          "ZeroMQ: {} subscriptions dropped ({} longer than {} bytes, {} beyond {} "
          "distinct ones)",
          dropped_long_ + dropped_over_cap_, dropped_long_, prefix_cap_, dropped_over_cap_,
          kMaxSubscriptions);
  }
  if (Subscribed("end"))
    Publish("end",
            {{"stamp", finish.time_sec},
             {"sim_step", finish.step},
             {"frame_id", ""},
             {"reason", reason},
             {"dropped", dropped}},
            zmq::message_t());
  // no more publications; requests from now on get `stopping` until the bridge is closed
  {
    std::lock_guard<std::mutex> lock(out_mu_);
    closing_ = true;
  }
  out_cv_.notify_all();
  stopping_.store(true);
  Wake(cmd_wake_fd_);
  Wake(pub_wake_fd_);
}

}  // namespace

void ZmqBridgeOptions::ValidateOrThrow() const {
  if (hwm < 1)
    throw ConfigError("", 0, "--zmq-hwm",
                      fmt::format("{} is below 1; expected messages >= 1", hwm));
  if (max_request_bytes < 64 || max_request_bytes > kHardMessageLimit)
    throw ConfigError(
        "", 0, "--zmq-max-request",
        fmt::format("{} bytes is outside [64, {}]", max_request_bytes, kHardMessageLimit));
  if (!(state_hz >= 0) || !std::isfinite(state_hz))
    throw ConfigError("", 0, "--zmq-state-hz",
                      fmt::format("{} is not a rate; expected Hz >= 0 (0 = every step)", state_hz));
  if (queue_capacity < 1)
    throw ConfigError("", 0, "--zmq", "the outgoing queue capacity must be >= 1");
  ResolveEndpoints();
}

std::pair<std::string, std::string> ZmqBridgeOptions::ResolveEndpoints() const {
  std::string host;
  int port = 0;
  std::string cmd = endpoint, pub = pub_endpoint;
  const bool tcp = SplitTcp(endpoint, &host, &port);
  if (!tcp && endpoint.rfind("ipc://", 0) != 0)
    throw ConfigError("", 0, "--zmq",
                      fmt::format("'{}' is not an endpoint; expected tcp://HOST:PORT (e.g. "
                                  "tcp://127.0.0.1:5555) or ipc://PATH",
                                  endpoint));
  if (!bind.empty() && tcp) cmd = fmt::format("tcp://{}:{}", bind, port);
  if (pub.empty()) {
    if (!tcp)
      throw ConfigError("", 0, "--zmq-pub",
                        "an ipc:// command endpoint needs the publish endpoint given "
                        "(--zmq-pub ipc://PATH)");
    if (port == 65535)
      throw ConfigError("", 0, "--zmq-pub",
                        "the command port is 65535, so port + 1 does not exist; give --zmq-pub");
    pub = fmt::format("tcp://{}:{}", bind.empty() ? host : bind, port + 1);
  } else {
    std::string phost;
    int pport = 0;
    const bool ptcp = SplitTcp(pub, &phost, &pport);
    if (!ptcp && pub.rfind("ipc://", 0) != 0)
      throw ConfigError("", 0, "--zmq-pub",
                        fmt::format("'{}' is not an endpoint; expected tcp://HOST:PORT or "
                                    "ipc://PATH",
                                    pub));
    if (ptcp && !bind.empty()) pub = fmt::format("tcp://{}:{}", bind, pport);
  }
  if (cmd == pub)
    throw ConfigError("", 0, "--zmq-pub",
                      fmt::format("the publish endpoint equals the command endpoint {}", cmd));
  return {cmd, pub};
}

RunBridgeFactory MakeZmqBridgeFactory(ZmqBridgeOptions options) {
  options.ValidateOrThrow();
  return [options](const RunBridgeContext& context) -> std::unique_ptr<RunBridge> {
    return std::make_unique<ZmqBridge>(context, options);
  };
}

}  // namespace penumbra
