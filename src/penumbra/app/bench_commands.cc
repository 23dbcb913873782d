#include "penumbra/app/bench_commands.h"

#include <CLI/CLI.hpp>
#include <optional>
#include <string>

#include "penumbra/app/backend_flag.h"
#include "penumbra/app/cli_options.h"
#include "penumbra/bench/bench.h"
#include "penumbra/bench/net/bench_bridge.h"
#include "penumbra/bench/net/bench_ros.h"
#include "penumbra/bench/net/bench_ros2.h"
#include "penumbra/bench/record/bench_record.h"
#include "penumbra/bench/sensors/sensor_bench.h"
#include "penumbra/core/error.h"

namespace penumbra {
namespace {

class BenchRenderCommand : public Command {
 public:
  std::string name() const override { return "bench render"; }
  std::string summary() const override { return "frames/s and Mrays/s at 640x480 and 800x800"; }

  void AddOptions(CLI::App* verb) override {
    verb_ = verb;
    verb->add_option("--world", options_.world_file, "world file (default: bundled default world)");
    AddInteger(verb, "--frames", &options_.frames, 1, 100000, "timed frames per resolution");
    AddInteger(verb, "--threads", &options_.threads, 0, 256, "render threads (0 = all cores)");
    verb->add_option("--tier", options_.tier, "render tier")
        ->check(CLI::IsMember({"realtime", "pathtraced"}));
    backend_.Add(verb);
    AddInteger(verb, "--batch", &options_.batch, 1, 65535,
               "batch rendering: N cameras per launch on the CUDA backend (depth+seg, then "
               "realtime rgb+depth; docs/gpu.md)");
    verb->add_option("--size", size_, "WxH of each camera in --batch (default 128x128)")
        ->check(CLI::Validator(
            [](std::string& v) -> std::string {
              const size_t x = v.find('x');
              const std::optional<uint64_t> w =
                  x == std::string::npos ? std::nullopt : ParseUnsigned(v.substr(0, x));
              const std::optional<uint64_t> h =
                  x == std::string::npos ? std::nullopt : ParseUnsigned(v.substr(x + 1));
              if (!w || !h || *w < 1 || *h < 1 || *w > 16384 || *h > 16384)
                return "'" + v + "' is not WxH with W and H in [1, 16384], e.g. 128x128";
              return "";
            },
            "WxH", ""));
    AddInteger(verb, "--sessions", &options_.sessions, 1, 64,
               "--batch: spread the cameras over this many sessions of the world (default 1)");
    verb->add_flag("--no-adversity", no_adversity_, "skip the none/minor/major preset lines");
    verb->add_option("--preset", options_.presets,
                     "time only these adversity presets' lines (none, minor, major; e.g. "
                     "--preset major to profile one condition) and skip the plain lines")
        ->delimiter(',')
        ->check(CLI::IsMember({"none", "minor", "major"}))
        ->excludes("--no-adversity");
    verb->add_option("--ablate", options_.ablate,
                     "switch parts of the CPU renderer off to time what they cost: mirror, "
                     "mirror-sparse, sky-volume, texture-filter, shadows, sun-occluder, "
                     "film (docs/performance.md)")
        ->delimiter(',');
    verb->add_flag("--only-640x480", options_.only_640x480, "time only 640x480 (skip 800x800)");
  }

  int Run(const CommandArgs&) override {
    options_.adversity = !no_adversity_;
    options_.backend = backend_.Resolve();
    if (!size_.empty() || verb_->count("--sessions") > 0) {
      if (options_.batch == 0)
        throw ConfigError("", 0, size_.empty() ? "--sessions" : "--size",
                          "applies to --batch only; expected it with --batch N");
    }
    if (!size_.empty()) {
      const size_t x = size_.find('x');
      options_.batch_width = static_cast<int>(*ParseUnsigned(size_.substr(0, x)));
      options_.batch_height = static_cast<int>(*ParseUnsigned(size_.substr(x + 1)));
    }
    return BenchRender(options_);
  }

 private:
  CLI::App* verb_ = nullptr;
  RenderBenchOptions options_;
  BackendFlag backend_;
  std::string size_;
  bool no_adversity_ = false;
};

class BenchPhysicsCommand : public Command {
 public:
  std::string name() const override { return "bench physics"; }
  std::string summary() const override { return "Penumbra physics steps/s vs a bare mj_step loop"; }

  void AddOptions(CLI::App* verb) override {
    verb->add_option("--world", options_.world_file, "world file (default: bundled default world)");
    verb->add_option("--model", options_.model_file,
                     "bare MJCF model, stepped and its peak memory compared with MuJoCo alone "
                     "(the world too when --world is given)");
    // internal: the child processes of the memory comparison
    verb->add_option("--memory-child", options_.memory_child)->group("");
    AddDecimal(
        verb, "--seconds", [this](double v) { options_.sim_seconds = v; }, 0, true,
        "simulated seconds per side");
    verb->add_flag("--no-controllers", no_controllers_,
                   "skip the controller-cost table of the bundled robot worlds");
  }

  int Run(const CommandArgs&) override {
    options_.controllers = !no_controllers_;
    return BenchPhysics(options_);
  }

 private:
  PhysicsBenchOptions options_;
  bool no_controllers_ = false;
};

class BenchRecordCommand : public Command {
 public:
  std::string name() const override { return "bench record"; }
  std::string summary() const override {
    return "physics steps/s with run-log recording on vs off, and the size of a 60 s log";
  }

  void AddOptions(CLI::App* verb) override {
    BenchRecordOptions& o = options_;
    verb->add_option("--world", o.world_file, "world file (default: bundled default world)");
    verb->add_option("--seconds", o.round_seconds, "simulated seconds per timed round")
        ->check(CLI::Range(0.01, 3600.0));
    verb->add_option("--rounds", o.rounds, "A/B rounds (off, on)")->check(CLI::Range(1, 100));
    verb->add_option("--size-seconds", o.size_seconds, "simulated seconds of the sized log")
        ->check(CLI::Range(0.01, 3600.0));
    verb->add_option("--log-dir", o.log_dir, "folder for the logs (default: temporary)");
    verb->add_option("--zstd-level", o.zstd_level, "the writer's zstd level")
        ->check(CLI::Range(1, 19));
  }

  int Run(const CommandArgs&) override { return BenchRecord(options_); }

 private:
  BenchRecordOptions options_;
};

class BenchBridgeCommand : public Command {
 public:
  std::string name() const override { return "bench bridge"; }
  std::string summary() const override {
    return "ZeroMQ bridge: lockstep round trip, free-running frames/s, physics with the bridge "
           "idle";
  }

  void AddOptions(CLI::App* verb) override {
    BenchBridgeOptions& o = options_;
    verb->add_option("--world", o.world_file, "world file (default: worlds/quadruped.yaml)");
    verb->add_option("--trips", o.trips, "lockstep round trips timed")
        ->check(CLI::Range(10, 1000000));
    verb->add_option("--seconds", o.seconds, "wall seconds of free-running frames")
        ->check(CLI::Range(0.1, 600.0));
    verb->add_option("--round-seconds", o.round_seconds, "simulated seconds per physics round")
        ->check(CLI::Range(0.01, 3600.0));
    verb->add_option("--rounds", o.rounds, "physics A/B rounds")->check(CLI::Range(1, 100));
  }

  int Run(const CommandArgs&) override { return BenchBridge(options_); }

 private:
  BenchBridgeOptions options_;
};

class BenchRosCommand : public Command {
 public:
  std::string name() const override { return "bench ros"; }
  std::string summary() const override {
    return "ROS 1 transport of 640x480 images: round trip and frames/s (needs roscore)";
  }

  void AddOptions(CLI::App* verb) override {
    verb->add_option("--seconds", options_.seconds, "wall seconds of the throughput phase")
        ->check(CLI::Range(0.5, 600.0));
    verb->add_option("--trips", options_.trips, "round trips timed")->check(CLI::Range(10, 100000));
    verb->add_option("--master", options_.master_uri, "ROS master URI (default $ROS_MASTER_URI)");
  }

  int Run(const CommandArgs&) override { return BenchRos(options_); }

 private:
  RosBenchOptions options_;
};

class BenchRos2Command : public Command {
 public:
  std::string name() const override { return "bench ros2"; }
  std::string summary() const override {
    return "ROS 2 transport (Cyclone DDS) of 640x480 images, Imu, /tf: latency, losses, "
           "lockstep round trip";
  }

  void AddOptions(CLI::App* verb) override {
    verb->add_option("--seconds", options_.seconds, "wall seconds of the streaming phase")
        ->check(CLI::Range(0.5, 600.0));
    verb->add_option("--trips", options_.trips, "lockstep round trips timed")
        ->check(CLI::Range(10, 100000));
    verb->add_option("--ros-domain", options_.domain,
                     "ROS domain id (default: one at random in 100..232)")
        ->check(CLI::Range(0, 232));
    verb->add_option("--ros-interface", options_.interface,
                     "IPv4 address of the one interface DDS uses (default 127.0.0.1)");
    verb->add_flag_callback(
        "--no-depth", [this] { options_.depth = false; },
        "rgb only: no depth image written beside each rgb image");
    verb->add_option("--receive-buffer", options_.receive_buffer,
                     "UDP receive buffer in bytes (Cyclone SocketReceiveBufferSize; default: the "
                     "system's, capped by net.core.rmem_max)")
        ->check(CLI::Range(int64_t{0}, int64_t{1} << 31));
  }

  int Run(const CommandArgs&) override { return BenchRos2(options_); }

 private:
  Ros2BenchOptions options_;
};

class BenchSensorsCommand : public Command {
 public:
  std::string name() const override { return "bench sensors"; }
  std::string summary() const override {
    return "LiDAR rays/s and ms/scan, IMU/MuJoCo sensor overhead";
  }

  void AddOptions(CLI::App* verb) override {
    verb->add_option("--world", options_.world_file, "world file (default: bundled default world)");
    AddInteger(verb, "--scans", &options_.scans, 1, 100000, "timed scans per LiDAR preset");
    AddDecimal(
        verb, "--seconds", [this](double v) { options_.seconds = v; }, 0, true,
        "simulated seconds for the sensor overhead");
  }

  int Run(const CommandArgs&) override { return BenchSensors(options_); }

 private:
  SensorBenchOptions options_;
};

}  // namespace

std::unique_ptr<Command> MakeBenchRenderCommand() { return std::make_unique<BenchRenderCommand>(); }
std::unique_ptr<Command> MakeBenchPhysicsCommand() {
  return std::make_unique<BenchPhysicsCommand>();
}
std::unique_ptr<Command> MakeBenchRecordCommand() { return std::make_unique<BenchRecordCommand>(); }
std::unique_ptr<Command> MakeBenchBridgeCommand() { return std::make_unique<BenchBridgeCommand>(); }
std::unique_ptr<Command> MakeBenchRosCommand() { return std::make_unique<BenchRosCommand>(); }
std::unique_ptr<Command> MakeBenchRos2Command() { return std::make_unique<BenchRos2Command>(); }
std::unique_ptr<Command> MakeBenchSensorsCommand() {
  return std::make_unique<BenchSensorsCommand>();
}

}  // namespace penumbra
