#include "penumbra/bench/net/bench_bridge.h"

#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <ctime>
#include <thread>
#include <vector>
#include <zmq.hpp>
#include <zmq_addon.hpp>

#include "penumbra/command/command_dispatcher.h"
#include "penumbra/command/run_bridge.h"
#include "penumbra/command/run_control.h"
#include "penumbra/command/run_description.h"
#include "penumbra/core/bench_machine.h"
#include "penumbra/core/build_info.h"
#include "penumbra/core/error.h"
#include "penumbra/physics/physics_source.h"
#include "penumbra/pipeline/sim_loop.h"
#include "penumbra/session/session.h"
#include "penumbra/zmq/msgpack_json.h"
#include "penumbra/zmq/zmq_bridge.h"

namespace penumbra {
namespace {

using Clock = std::chrono::steady_clock;
using json = nlohmann::json;

double Seconds(Clock::time_point a, Clock::time_point b) {
  return std::chrono::duration<double>(b - a).count();
}

double ProcessCpuSec() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

double Percentile(std::vector<double> v, double p) {
  std::sort(v.begin(), v.end());
  if (v.empty()) return 0;
  const size_t i = std::min(v.size() - 1, static_cast<size_t>(p * static_cast<double>(v.size())));
  return v[i];
}

double Median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  if (n == 0) return 0;
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

// a world set up for live runs: session (no renderer), RunControl, dispatcher, optionally the
// ZeroMQ bridge on a free loopback port pair
struct Live {
  std::unique_ptr<Session> session;
  json model_info;
  std::unique_ptr<RunControl> control;
  std::unique_ptr<CommandDispatcher> dispatcher;
  std::unique_ptr<RunBridge> bridge;
  std::string endpoint;

  Live(const WorldConfig& world, bool paused, bool with_bridge, int hwm) {
    SessionOptions so;
    so.build_renderer = false;
    session = std::make_unique<Session>(world, so);
    model_info = DescribeRun(*session, session->world());
    RunControlOptions co;
    co.start_paused = paused;
    control = std::make_unique<RunControl>(&session->sim(), co);
    dispatcher = std::make_unique<CommandDispatcher>(*session, session->world(), control.get(),
                                                     model_info, paused);
    if (!with_bridge) return;
    const int base = 40000 + static_cast<int>(::getpid() % 5000) * 4;
    for (int attempt = 0; attempt < 64 && !bridge; ++attempt) {
      ZmqBridgeOptions o;
      o.endpoint = fmt::format("tcp://127.0.0.1:{}", base + 2 * attempt);
      o.hwm = hwm;
      try {
        bridge = MakeZmqBridgeFactory(o)(
            RunBridgeContext{*session, session->world(), *dispatcher, *control, model_info});
        endpoint = o.endpoint;
      } catch (const Error&) {
      }
    }
    if (!bridge) throw Error("bench bridge: no free loopback port pair for the ZeroMQ bridge");
  }
};

// publishes a copy of a pre-rendered frame at every physics step (as CameraSink hands each
// rendered frame to the bridges: one copy into a shared frame)
class FrameInjector : public Sink {
 public:
  FrameInjector(RunBridge* bridge, int width, int height) : bridge_(bridge) {
    proto_.camera = "bench";
    proto_.rgb = ImageU8(width, height, 3);
    for (size_t i = 0; i < proto_.rgb.data.size(); ++i)
      proto_.rgb.data[i] = static_cast<uint8_t>((i * 7) & 0xff);
  }
  SnapshotContent Wants(int64_t, double) override { return SnapshotContent::kState; }
  void OnSnapshot(const std::shared_ptr<const WorldSnapshot>& s) override {
    if (!bridge_) return;
    auto f = std::make_shared<CameraFrame>(proto_);
    f->step = s->step;
    f->time_sec = s->time_sec;
    f->index = frames_++;
    bridge_->OnCameraFrame(f);
  }
  int64_t frames() const { return frames_; }

 private:
  RunBridge* bridge_;
  CameraFrame proto_;
  int64_t frames_ = 0;
};

// a Live world stepped by a SimLoop (not started): the RunControl's BeforeStep before every
// step, its stop flag, and as sinks the RunControl, a FrameInjector (publishing through the
// bridge when there is one) and the bridge
struct LiveLoop {
  Live live;
  FrameInjector injector;
  PhysicsSource physics;
  SimLoop loop;

  LiveLoop(const WorldConfig& world, bool paused, bool with_bridge, int hwm, int width, int height)
      : live(world, paused, with_bridge, hwm),
        injector(live.bridge.get(), width, height),
        physics(&live.session->sim(), PhysicsOptions(live.control.get())),
        loop(&physics, LoopOptions(live.control.get())) {
    loop.AddSink(live.control.get());
    loop.AddSink(&injector);
    if (live.bridge) loop.AddSink(live.bridge.get());
  }

 private:
  static PhysicsSourceOptions PhysicsOptions(RunControl* control) {
    PhysicsSourceOptions po;
    po.before_step = [control](Simulation& s) { return control->BeforeStep(s); };
    return po;
  }
  static SimLoopOptions LoopOptions(RunControl* control) {
    SimLoopOptions lo;
    lo.stop_request = control->stop_flag();
    return lo;
  }
};

// a REQ + SUB client of the bridge in this process
struct Client {
  zmq::context_t ctx{1};
  zmq::socket_t req{ctx, zmq::socket_type::req};
  zmq::socket_t sub{ctx, zmq::socket_type::sub};

  explicit Client(const std::string& endpoint) {
    req.set(zmq::sockopt::linger, 0);
    req.set(zmq::sockopt::rcvtimeo, 20000);
    sub.set(zmq::sockopt::linger, 0);
    sub.set(zmq::sockopt::rcvtimeo, 20000);
    req.connect(endpoint);
    const json hello = Call({{"cmd", "hello"}, {"protocol", 1}});
    sub.connect(hello.at("pub_endpoint").get<std::string>());
    sub.set(zmq::sockopt::subscribe, "camera/");
    sub.set(zmq::sockopt::subscribe, "sync");
    for (int i = 0;; ++i) {
      Call({{"cmd", "sync"}, {"token", "b"}});
      zmq::pollitem_t item{sub.handle(), 0, ZMQ_POLLIN, 0};
      if (zmq::poll(&item, 1, std::chrono::milliseconds(50)) > 0) {
        std::vector<zmq::message_t> parts;
        (void)zmq::recv_multipart(sub, std::back_inserter(parts));
        if (!parts.empty() && parts[0].to_string() == "sync") break;
      }
      if (i > 400) throw Error("bench bridge: the subscription never reached the server");
    }
    sub.set(zmq::sockopt::unsubscribe, "sync");
  }

  json Call(const json& request) {
    const std::string b = EncodeMsgpack(request);
    req.send(zmq::buffer(b), zmq::send_flags::none);
    zmq::message_t reply;
    if (!req.recv(reply)) throw Error("bench bridge: no reply within 20 s");
    json r = DecodeMsgpack(reply.data(), reply.size());
    if (!r.value("ok", false)) throw Error("bench bridge: " + r.dump());
    return r;
  }

  // receives one message; returns its topic
  std::string Receive(size_t* payload_bytes) {
    std::vector<zmq::message_t> parts;
    if (!zmq::recv_multipart(sub, std::back_inserter(parts)) || parts.size() != 3)
      throw Error("bench bridge: no frame within 20 s");
    *payload_bytes = parts[2].size();
    return parts[0].to_string();
  }
  // drops whatever waits on the SUB socket
  void Drain() {
    std::vector<zmq::message_t> parts;
    while (zmq::recv_multipart(sub, std::back_inserter(parts), zmq::recv_flags::dontwait))
      parts.clear();
  }
};

struct PhysicsRound {
  double steps_per_sec = 0;
  double cpu_us_per_step = 0;
};

PhysicsRound RunPhysics(const WorldConfig& world, double seconds, bool with_bridge) {
  std::unique_ptr<Live> live;
  std::unique_ptr<Session> bare;
  PhysicsSourceOptions po;
  SimLoopOptions lo;
  lo.end_time_sec = seconds;
  Simulation* sim = nullptr;
  if (with_bridge) {
    live = std::make_unique<Live>(world, false, true, 1000);
    RunControl* control = live->control.get();
    po.before_step = [control](Simulation& s) { return control->BeforeStep(s); };
    lo.stop_request = control->stop_flag();
    sim = &live->session->sim();
  } else {
    SessionOptions so;
    so.build_renderer = false;
    bare = std::make_unique<Session>(world, so);
    sim = &bare->sim();
  }
  PhysicsSource physics(sim, po);
  SimLoop loop(&physics, lo);
  if (live) {
    loop.AddSink(live->control.get());
    loop.AddSink(live->bridge.get());
  }
  const auto t0 = Clock::now();
  const double c0 = ProcessCpuSec();
  const LoopFinish f = loop.Run();
  const double cpu = ProcessCpuSec() - c0;
  const double wall = Seconds(t0, Clock::now());
  if (f.error) std::rethrow_exception(f.error);
  PhysicsRound r;
  r.steps_per_sec = static_cast<double>(physics.step()) / std::max(wall, 1e-9);
  r.cpu_us_per_step = 1e6 * cpu / static_cast<double>(std::max<int64_t>(physics.step(), 1));
  return r;
}

}  // namespace

int BenchBridge(const BenchBridgeOptions& o) {
  WorldConfig world = LoadWorldFile(o.world_file.empty() ? std::string(PENUMBRA_SOURCE_DIR) +
                                                               "/worlds/quadruped.yaml"
                                                         : o.world_file);
  world.render.seed = world.seed;
  world.duration_sec = 1e6;
  constexpr int kWidth = 640, kHeight = 480;
  fmt::print("bench bridge: {} (tcp loopback, client in this process, {} hardware threads)\n",
             world.file, std::thread::hardware_concurrency());

  // 1. lockstep round trip: step n=1 + one 640x480 RGB frame, against the dispatcher alone
  std::vector<double> rt, base;
  {
    LiveLoop l(world, true, false, 1000, kWidth, kHeight);
    Live& live = l.live;
    l.loop.Start();
    const json step = {{"cmd", "step"}, {"n", 1}};
    live.dispatcher->Call(step);
    for (int i = 0; i < o.trips; ++i) {
      const auto t0 = Clock::now();
      const json r = live.dispatcher->Call(step);
      base.push_back(Seconds(t0, Clock::now()));
      if (!r.value("ok", false)) throw Error("bench bridge: " + r.dump());
    }
    live.dispatcher->Call({{"cmd", "stop"}});
    l.loop.Wait();
  }
  {
    LiveLoop l(world, true, true, 1000, kWidth, kHeight);
    Live& live = l.live;
    l.loop.Start();
    Client client(live.endpoint);
    const json step = {{"cmd", "step"}, {"n", 1}};
    client.Call(step);  // steps 0 and 1: two frames
    size_t bytes = 0;
    client.Receive(&bytes);
    client.Receive(&bytes);
    for (int i = 0; i < o.trips; ++i) {
      const auto t0 = Clock::now();
      const json r = client.Call(step);
      const std::string topic = client.Receive(&bytes);
      rt.push_back(Seconds(t0, Clock::now()));
      if (topic != "camera/bench/rgb" || bytes != size_t{kWidth} * kHeight * 3 ||
          r.at("published").value("camera/bench/rgb", 0) != 1)
        throw Error(fmt::format("bench bridge: unexpected {} of {} bytes", topic, bytes));
    }
    client.Call({{"cmd", "stop"}});
    l.loop.Wait();
  }
  const double rt_med = Median(rt), base_med = Median(base);
  fmt::print(
      "lockstep step + 640x480 rgb8 frame: round trip median {:.3f} ms, p99 {:.3f} ms over {} "
      "trips\n  in-process step alone: median {:.3f} ms, p99 {:.3f} ms\n  added by the bridge: "
      "median {:.3f} ms ({}: < 1 ms: {})\n",
      1e3 * rt_med, 1e3 * Percentile(rt, 0.99), o.trips, 1e3 * base_med,
      1e3 * Percentile(base, 0.99), 1e3 * (rt_med - base_med), BenchTargetLabel(),
      BenchTargetVerdict(rt_med - base_med < 1e-3, ThisMachine()));

  // 2. free-running: a pre-rendered frame at every physics step, frames/s one subscriber gets
  {
    LiveLoop l(world, false, true, 16, kWidth, kHeight);
    Live& live = l.live;
    Client client(live.endpoint);  // subscribed before the loop starts
    l.loop.Start();
    size_t bytes = 0;
    client.Receive(&bytes);
    int64_t frames = 0;
    const int64_t steps0 = live.control->boundary_step();
    const auto t0 = Clock::now();
    while (Seconds(t0, Clock::now()) < o.seconds) {
      client.Receive(&bytes);
      if (bytes != size_t{kWidth} * kHeight * 3) throw Error("bench bridge: short frame");
      ++frames;
    }
    const double wall = Seconds(t0, Clock::now());
    const int64_t steps = live.control->boundary_step() - steps0;
    live.control->RequestStop();
    l.loop.Wait();
    fmt::print(
        "free-running 640x480 rgb8: {:.0f} frames/s received by one subscriber ({}: >= 300: "
        "{}); {:.0f} physics steps/s publishing a frame each ({:.0f} % of them delivered, the "
        "rest dropped by the queue / high-water mark)\n",
        static_cast<double>(frames) / wall, BenchTargetLabel(),
        BenchTargetVerdict(static_cast<double>(frames) / wall >= 300, ThisMachine()),
        static_cast<double>(steps) / wall,
        100.0 * static_cast<double>(frames) / std::max<double>(1, static_cast<double>(steps)));
  }

  // 3. physics steps/s with the bridge attached and idle against no bridge
  std::vector<double> off, on, cpu_off, cpu_on;
  for (int i = 0; i < o.rounds; ++i) {
    const PhysicsRound a = RunPhysics(world, o.round_seconds, false);
    const PhysicsRound b = RunPhysics(world, o.round_seconds, true);
    off.push_back(a.steps_per_sec);
    on.push_back(b.steps_per_sec);
    cpu_off.push_back(a.cpu_us_per_step);
    cpu_on.push_back(b.cpu_us_per_step);
    fmt::print(
        "  round {}: no bridge {:7.0f} steps/s   bridge idle {:7.0f} steps/s   ratio {:.3f}\n",
        i + 1, a.steps_per_sec, b.steps_per_sec, b.steps_per_sec / a.steps_per_sec);
  }
  fmt::print(
      "physics with the bridge idle: median {:.0f} vs {:.0f} steps/s, ratio {:.3f} (target >= "
      "0.95); CPU {:.1f} vs {:.1f} us/step\n",
      Median(on), Median(off), Median(on) / Median(off), Median(cpu_on), Median(cpu_off));
  return 0;
}

}  // namespace penumbra
