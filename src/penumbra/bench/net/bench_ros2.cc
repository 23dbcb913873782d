#include "penumbra/bench/net/bench_ros2.h"

#include <fmt/format.h>

#include <cstdio>

#include "penumbra/core/bench_machine.h"

namespace penumbra {

int BenchRos2(const Ros2BenchOptions& o) {
  const Ros2BenchResult r = RunRos2Bench(o);
  std::printf("%s",
              fmt::format("ROS 2 transport over Cyclone DDS (DDS-RTPS over UDP on {}, domain {}), "
                          "subscriber in another process, UDP receive buffer {}\n",
                          o.interface, r.domain,
                          o.receive_buffer > 0 ? fmt::format("{} bytes", o.receive_buffer)
                                               : std::string("the system's default"))
                  .c_str());
  std::printf("%s", fmt::format("  {:.1f} s of {}x{} rgb8{} at {:g} Hz, Imu at {:g} Hz, /tf at "
                                "{:g} Hz; latency = publish -> taken by the subscriber\n",
                                o.seconds, o.width, o.height, o.depth ? " + 32FC1" : "",
                                o.camera_hz, o.imu_hz, o.tf_hz)
                        .c_str());
  std::printf("  %-24s %-24s %8s %8s %6s %10s %10s %10s\n", "topic", "QoS", "sent", "received",
              "lost", "median ms", "p99 ms", "max ms");
  bool lost = false, slow = false;
  for (const Ros2TopicStats& t : r.topics) {
    if (t.sent == 0) continue;
    std::printf(
        "%s",
        fmt::format("  {:<24} {:<24} {:>8} {:>8} {:>6} {:>10.3f} {:>10.3f} {:>10.3f}\n", t.topic,
                    t.qos, t.sent, t.received, t.sent - t.received, t.median_ms, t.p99_ms, t.max_ms)
            .c_str());
    if (t.received < t.sent) lost = true;
    if (t.median_ms >= 1.0) slow = true;
  }
  std::printf("%s", fmt::format("  {}: added latency < 1 ms (median): {}; no message lost: {}\n",
                                BenchTargetLabel(), BenchTargetVerdict(!slow, ThisMachine()),
                                lost ? "NOT met" : "met")
                        .c_str());
  std::printf("%s", fmt::format("  lockstep round trip (Trigger request -> {}x{} rgb8 frame and "
                                "reply), {} trips: median {:.3f} ms, p99 {:.3f} ms, {} requests "
                                "sent again   {}: < 2 ms: {}\n",
                                o.width, o.height, r.trips, r.trip_median_ms, r.trip_p99_ms,
                                r.trips_resent, BenchTargetLabel(),
                                BenchTargetVerdict(r.trip_median_ms < 2.0, ThisMachine()))
                        .c_str());
  return 0;
}

}  // namespace penumbra
