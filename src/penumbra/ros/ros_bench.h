#pragma once
// the ROS 1 transport benchmark of `penumbra bench ros` (docs/ros.md, docs/performance.md):
// 640x480 rgb8 sensor_msgs/Image messages from this process to a subscriber in a child process
// (a second roscpp node, forked before this one starts), over roscpp's TCP transport on loopback
// through a running master:
//   1. round trip: one frame published, the subscriber answers with a small message
//      (rosgraph_msgs/Clock carrying the frame's stamp); send -> answer, median and p99;
//   2. throughput: a pre-rendered frame published back to back for `seconds`; the frames per
//      second the subscriber receives (its own count over its own first-to-last time).
// a benchmark, never a pass/fail test. C++17 header (ros/ros1/ros_bench.cc).

#include <cstdint>
#include <string>

namespace penumbra {

/// settings of the ROS transport benchmark.
struct RosBenchOptions {
  std::string master_uri;  ///< "" = $ROS_MASTER_URI
  int width = 640, height = 480;
  int trips = 200;       ///< round trips timed
  double seconds = 3.0;  ///< wall seconds of the throughput phase
  int queue_size = 10;   ///< publisher and subscriber queue (messages)
};

/// what the benchmark measured.
struct RosBenchResult {
  double trip_median_ms = 0, trip_p99_ms = 0;
  int64_t frames_sent = 0;       ///< throughput phase, published
  int64_t frames_received = 0;   ///< throughput phase, received by the subscriber
  double received_per_sec = 0;   ///< received frames / subscriber's receive span
  double megabytes_per_sec = 0;  ///< received image bytes / s, MB (1e6)
};

/// runs the benchmark. must be called before anything else in the process starts ROS (it
/// forks).
/// @throws Error when no master answers, the subscriber does not connect within 10 s, or this
///         build has no ROS 1.
RosBenchResult RunRosBench(const RosBenchOptions& options);

}  // namespace penumbra
