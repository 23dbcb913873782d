#include "penumbra/bench/net/viewer_bench.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <atomic>
#include <boost/asio/connect.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/websocket.hpp>
#include <chrono>
#include <filesystem>
#include <mutex>
#include <nlohmann/json.hpp>
#include <thread>

#include "penumbra/core/bench_machine.h"
#include "penumbra/core/error.h"
#include "penumbra/run/runner.h"
#include "penumbra/viewer/viewer_bridge.h"
#include "penumbra/viewer/viewer_messages.h"
#include "penumbra/world/default_world.h"
#include "penumbra/world/world_config.h"

namespace penumbra {

namespace {

namespace beast = boost::beast;
namespace websocket = beast::websocket;
namespace net = boost::asio;
using tcp = net::ip::tcp;
using nlohmann::json;
using Clock = std::chrono::steady_clock;

double Seconds(Clock::duration d) { return std::chrono::duration<double>(d).count(); }

// what TimingBridge measured (outlives the bridge, which ends with the run)
struct LoopTiming {
  double wall_sec = 0;
  int64_t steps = 0;
  double steps_per_sec() const { return wall_sec > 0 ? steps / wall_sec : 0; }
};

// times the loop: from its start to its end, and the steps taken
class TimingBridge : public RunBridge {
 public:
  explicit TimingBridge(LoopTiming* out) : out_(out) {}
  void OnStart(const LoopStart& s) override {
    t0_ = Clock::now();
    step0_ = s.step;
  }
  void OnFinish(const LoopFinish& f) override {
    out_->wall_sec = Seconds(Clock::now() - t0_);
    out_->steps = f.step - step0_;
  }

 private:
  LoopTiming* out_;
  Clock::time_point t0_;
  int64_t step0_ = 0;
};

// a page stand-in: one WebSocket client that subscribes to a stream, counts the frames it is
// delivered and, with `teleop`, times twist commands to the first frame captured after them
struct BenchPage {
  std::string stream;
  bool teleop = false;
  int latency_samples = 0;
  std::atomic<int64_t> frames{0};
  std::atomic<int64_t> bytes{0};
  std::mutex mu;
  std::vector<double> latencies_ms;
  Clock::time_point first_frame, last_frame;
  std::thread thread;

  void Start(const std::string& url) {
    // url = http://HOST:PORT/?token=TOKEN (the page's URL: the WebSocket needs its token)
    const size_t slash = url.find('/', 7);
    const std::string hostport = url.substr(7, slash - 7);
    const size_t colon = hostport.rfind(':');
    const std::string host = hostport.substr(0, colon);
    const std::string port = hostport.substr(colon + 1);
    const size_t token_at = url.find("?token=");
    const std::string token = token_at == std::string::npos ? "" : url.substr(token_at + 7);
    thread = std::thread([this, host, port, token] {
      try {
        Run(host, port, token);
      } catch (const std::exception&) {
        // the run ended and the server closed the connection
      }
    });
  }

  void Run(const std::string& host, const std::string& port, const std::string& token) {
    net::io_context ioc;
    tcp::resolver resolver(ioc);
    websocket::stream<tcp::socket> ws(ioc);
    net::connect(ws.next_layer(), resolver.resolve(host, port));
    ws.read_message_max(64 << 20);
    ws.handshake(host + ":" + port, "/ws?token=" + token);
    ws.text(true);
    ws.write(net::buffer(json{{"cmd", "subscribe"}, {"id", 0}, {"streams", {stream}}}.dump()));
    int next_id = 1, waiting_id = -1;
    int64_t applied_step = -1;
    Clock::time_point sent, last_send = Clock::now();
    double vx = 0.3;
    beast::flat_buffer b;
    for (;;) {
      ws.read(b);
      const Clock::time_point now = Clock::now();
      const bool text = ws.got_text();
      const std::string m = beast::buffers_to_string(b.data());
      b.consume(b.size());
      if (!text) {
        const auto [header, jpeg] = UnpackFrameMessage(m);
        if (frames++ == 0) first_frame = now;
        last_frame = now;
        bytes += static_cast<int64_t>(m.size());
        if (applied_step >= 0 && header.value("step", int64_t{-1}) >= applied_step) {
          std::lock_guard<std::mutex> lock(mu);
          latencies_ms.push_back(1e3 * Seconds(now - sent));
          applied_step = -1;
        }
      } else {
        const json j = json::parse(m);
        if (j.contains("id") && j["id"] == waiting_id) {
          waiting_id = -1;
          applied_step = j.value("step", int64_t{-1});
        }
      }
      std::lock_guard<std::mutex> lock(mu);
      if (teleop && waiting_id < 0 && applied_step < 0 &&
          static_cast<int>(latencies_ms.size()) < latency_samples &&
          Seconds(now - last_send) > 0.4) {
        waiting_id = next_id++;
        sent = last_send = Clock::now();
        ws.text(true);
        ws.write(net::buffer(json{{"cmd", "twist"}, {"id", waiting_id}, {"vx", vx}}.dump()));
        vx = vx > 0 ? 0.0 : 0.3;
      }
    }
  }

  double FramesPerSec() const {
    const int64_t n = frames.load();
    const double dt = Seconds(last_frame - first_frame);
    return n > 1 && dt > 0 ? (n - 1) / dt : 0;
  }
};

struct ViewerRound {
  double steps_per_sec = 0;
  double frames_per_sec = 0;
  double kbytes_per_frame = 0;
  std::vector<double> latencies_ms;
};

ViewerRound RunViewerRound(const WorldConfig& world, double seconds, bool viewer, bool realtime,
                           int latency_samples) {
  ViewerRound r;
  const std::string out =
      (std::filesystem::temp_directory_path() / fmt::format("penumbra_bench_viewer_{}", ::getpid()))
          .string();
  std::filesystem::remove_all(out);
  RunOptions o;
  o.out_dir = out;
  o.duration_sec = seconds;
  o.progress = false;
  o.realtime = realtime;
  LoopTiming timing;
  o.bridges.push_back([&timing](const RunBridgeContext&) -> std::unique_ptr<RunBridge> {
    return std::make_unique<TimingBridge>(&timing);
  });
  BenchPage page;
  page.stream = "camera/" + world.cameras.front().name + "/rgb";
  page.teleop = latency_samples > 0;
  page.latency_samples = latency_samples;
  if (viewer) {
    ViewerOptions v;
    v.port = 0;
    v.on_listening = [&page](const std::string& url) { page.Start(url); };
    o.bridges.push_back(MakeViewerBridgeFactory(v));
  }
  RunWorld(world, o);  // the viewer (and its server) is gone once it returns
  if (page.thread.joinable()) page.thread.join();
  std::filesystem::remove_all(out);
  r.steps_per_sec = timing.steps_per_sec();
  r.frames_per_sec = page.FramesPerSec();
  r.kbytes_per_frame = page.frames ? page.bytes.load() / 1e3 / page.frames.load() : 0;
  r.latencies_ms = page.latencies_ms;
  return r;
}

double ViewerMedian(std::vector<double> v) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  return v.size() % 2 ? v[v.size() / 2] : 0.5 * (v[v.size() / 2 - 1] + v[v.size() / 2]);
}

}  // namespace

int BenchViewer(const BenchViewerOptions& options) {
  WorldConfig world =
      LoadWorldFile(options.world_file.empty() ? DefaultWorldPath() : options.world_file);
  if (world.cameras.empty())
    throw ConfigError(world.file, 0, "cameras",
                      "the viewer benchmark streams the world's first camera; the world has none");
  // one camera, rgb only, at the streamed rate
  world.cameras.resize(1);
  world.cameras[0].outputs = CameraOutputs{};
  world.cameras[0].rate_hz = options.camera_hz;
  world.mjcf_cameras.enabled = false;
  world.sensors.clear();
  const auto& cam = world.cameras[0];
  fmt::print(
      "penumbra bench viewer: {} camera '{}' {}x{} rgb at {} Hz, {} s per run, {} round(s), "
      "{} core(s)\n",
      world.file, cam.name, cam.width, cam.height, options.camera_hz, options.seconds,
      options.rounds, std::thread::hardware_concurrency());
  std::vector<double> without, with, fps, kb;
  for (int i = 0; i < options.rounds; ++i) {
    const ViewerRound a = RunViewerRound(world, options.seconds, false, false, 0);
    const ViewerRound b = RunViewerRound(world, options.seconds, true, false, 0);
    fmt::print(
        "  round {}: steps/s without viewer {:.0f}, with a page attached {:.0f} (ratio "
        "{:.3f}); frames delivered {:.1f}/s, {:.0f} kB/frame\n",
        i + 1, a.steps_per_sec, b.steps_per_sec, b.steps_per_sec / a.steps_per_sec,
        b.frames_per_sec, b.kbytes_per_frame);
    without.push_back(a.steps_per_sec);
    with.push_back(b.steps_per_sec);
    fps.push_back(b.frames_per_sec);
    kb.push_back(b.kbytes_per_frame);
  }
  const double ratio = ViewerMedian(with) / ViewerMedian(without);
  fmt::print(
      "physics steps/s (as fast as possible, median): without viewer {:.0f}, with viewer "
      "and one page {:.0f}: ratio {:.3f} (target >= 0.95)\n",
      ViewerMedian(without), ViewerMedian(with), ratio);
  fmt::print(
      "frames/s delivered to the page, {}x{} camera (median): {:.1f} ({}: >= 20: {}; the "
      "renderer's rate is the limit), {:.0f} kB/frame\n",
      cam.width, cam.height, ViewerMedian(fps), BenchTargetLabel(),
      BenchTargetVerdict(ViewerMedian(fps) >= 20, ThisMachine()), ViewerMedian(kb));
  if (options.latency_samples > 0) {
    const double seconds = std::max(options.seconds, 0.6 * options.latency_samples + 2);
    const ViewerRound rt = RunViewerRound(world, seconds, true, true, options.latency_samples);
    std::vector<double> l = rt.latencies_ms;
    std::sort(l.begin(), l.end());
    if (l.empty()) {
      fmt::print("input-to-photon latency: no sample (no frame arrived after a command)\n");
    } else {
      fmt::print(
          "input-to-photon latency at real-time pacing (teleop twist sent -> first frame "
          "captured after it received), {} samples: median {:.0f} ms, min {:.0f}, max "
          "{:.0f} ({}: < 100 ms: {}); frames {:.1f}/s\n",
          l.size(), ViewerMedian(l), l.front(), l.back(), BenchTargetLabel(),
          BenchTargetVerdict(ViewerMedian(l) < 100, ThisMachine()), rt.frames_per_sec);
    }
  }
  return 0;
}

}  // namespace penumbra
