#include "penumbra/bench/bench_ros.h"

#include <fmt/format.h>

#include <CLI/CLI.hpp>
#include <cstdio>

namespace penumbra {

int BenchRosCommand::Run() const {
  const RosBenchResult r = RunRosBench(options);
  std::printf("%s", fmt::format("ROS 1 transport, {}x{} rgb8 sensor_msgs/Image, roscpp TCP on "
                                "loopback, subscriber in another process\n",
                                options.width, options.height)
                        .c_str());
  std::printf("%s", fmt::format("  round trip (frame out, answer back), {} trips: median {:.3f} "
                                "ms, p99 {:.3f} ms\n",
                                options.trips, r.trip_median_ms, r.trip_p99_ms)
                        .c_str());
  std::printf("%s",
              fmt::format("  free-running, {:.1f} s: {} frames published, {} received = "
                          "{:.1f} frames/s ({:.0f} MB/s)   target >= 100 frames/s: {}\n",
                          options.seconds, r.frames_sent, r.frames_received, r.received_per_sec,
                          r.megabytes_per_sec, r.received_per_sec >= 100 ? "met" : "NOT met")
                  .c_str());
  return 0;
}

std::unique_ptr<BenchRosCommand> AddBenchRosCommand(CLI::App& bench) {
  auto c = std::make_unique<BenchRosCommand>();
  c->app = bench.add_subcommand(
      "ros", "ROS 1 transport of 640x480 images: round trip and frames/s (needs roscore)");
  c->app->add_option("--seconds", c->options.seconds, "wall seconds of the throughput phase")
      ->check(CLI::Range(0.5, 600.0));
  c->app->add_option("--trips", c->options.trips, "round trips timed")
      ->check(CLI::Range(10, 100000));
  c->app->add_option("--master", c->options.master_uri, "ROS master URI (default $ROS_MASTER_URI)");
  return c;
}

}  // namespace penumbra
