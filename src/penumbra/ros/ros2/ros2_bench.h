#pragma once
// the ROS 2 transport benchmark of `penumbra bench ros2` (docs/ros.md, docs/performance.md):
// ROS 2 messages over Cyclone DDS (DDS-RTPS, UDP) on one interface, from this process to a
// subscriber in a child process (a second DDS participant, forked before this one starts DDS),
// with the types, topic names and QoS of the bridge (ROS 2's sensor-data profile for images and
// IMU: BEST_EFFORT, KEEP_LAST 5; /tf: RELIABLE, KEEP_LAST 100):
//   1. streams for `seconds`: a 640x480 rgb8 Image and a 32FC1 depth Image at camera_hz, an Imu
//      at imu_hz, a TFMessage at tf_hz (the physics rate), each sample stamped with the
//      publisher's monotonic clock just before it is written; the subscriber notes the time it
//      takes each sample: latency per message (publish -> received, median, p99, max) and the
//      samples lost (sent - received) per topic;
//   2. lockstep round trip: the subscriber calls a std_srvs/Trigger service as rmw_cyclonedds
//      does (request header + request on rq/...Request); the publisher answers with one rgb
//      frame and the reply; request -> frame and reply received, median and p99. the
//      simulation's own step and render time are not part of it (bench bridge measures those).
// a benchmark, never a pass/fail test. no Cyclone header here: the build without ROS 2 has the
// same entry point (ros/no_ros2/), which throws.

#include <cstdint>
#include <string>
#include <vector>

namespace penumbra {

/// settings of the ROS 2 transport benchmark.
struct Ros2BenchOptions {
  int domain = -1;                      ///< ROS domain id 0..232; -1 = one at random in 100..232
  std::string interface = "127.0.0.1";  ///< numeric address of the one interface both use
  int width = 640, height = 480;        ///< image size (pixels)
  double seconds = 5.0;                 ///< wall seconds of the streaming phase
  /// messages per wall second
  double camera_hz = 30, imu_hz = 400, tf_hz = 500;
  bool depth = true;  ///< false: rgb only (no depth image written beside each rgb one)
  int trips = 200;    ///< lockstep round trips timed
  /// UDP receive buffer of both participants (bytes, Cyclone's Internal/SocketReceiveBufferSize
  /// min); 0 = Cyclone's default, the system's net.core.rmem_default, as a ROS 2 node without a
  /// CYCLONEDDS_URI has. Linux caps it at net.core.rmem_max.
  int64_t receive_buffer = 0;
};

/// what one topic of the streaming phase measured.
struct Ros2TopicStats {
  std::string topic;  ///< ROS name, e.g. "/bench/image_raw"
  std::string qos;    ///< e.g. "BEST_EFFORT KEEP_LAST 5"
  int64_t sent = 0, received = 0;
  double median_ms = 0, p99_ms = 0, max_ms = 0;  ///< publish -> received
  int64_t bytes = 0;  ///< serialized payload of one message (approximate: the data fields)
};

/// what the benchmark measured.
struct Ros2BenchResult {
  int domain = 0;
  std::vector<Ros2TopicStats> topics;
  double trip_median_ms = 0, trip_p99_ms = 0;
  int trips = 0;
  int trips_resent = 0;  ///< requests sent again: frame or reply not there after 1 s
};

/// runs the benchmark. it forks: call it before anything else in the process starts DDS.
/// @throws Error on a bad option (domain out of 0..232, interface not a numeric address, a size
///         or rate out of range), when DDS cannot start on the interface, when the subscriber
///         does not match within 20 s or does not report, or when this build has no ROS 2.
Ros2BenchResult RunRos2Bench(const Ros2BenchOptions& options);

}  // namespace penumbra
