#include "penumbra/bench/net/bench_ros.h"

#include <fmt/format.h>

#include <cstdio>

#include "penumbra/core/bench_machine.h"

namespace penumbra {

int BenchRos(const RosBenchOptions& options) {
  const RosBenchResult r = RunRosBench(options);
  std::printf("%s", fmt::format("ROS 1 transport, {}x{} rgb8 sensor_msgs/Image, roscpp TCP on "
                                "loopback, subscriber in another process\n",
                                options.width, options.height)
                        .c_str());
  std::printf("%s", fmt::format("  round trip (frame out, answer back), {} trips: median {:.3f} "
                                "ms, p99 {:.3f} ms\n",
                                options.trips, r.trip_median_ms, r.trip_p99_ms)
                        .c_str());
  std::printf("%s", fmt::format("  free-running, {:.1f} s: {} frames published, {} received = "
                                "{:.1f} frames/s ({:.0f} MB/s)   {}: >= 100 frames/s: {}\n",
                                options.seconds, r.frames_sent, r.frames_received,
                                r.received_per_sec, r.megabytes_per_sec, BenchTargetLabel(),
                                BenchTargetVerdict(r.received_per_sec >= 100, ThisMachine()))
                        .c_str());
  return 0;
}

}  // namespace penumbra
