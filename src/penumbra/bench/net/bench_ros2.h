#pragma once
// `penumbra bench ros2 [--seconds S] [--trips N] [--ros-domain N] [--ros-interface ADDR]
// [--receive-buffer BYTES]`: the ROS 2 transport cost of the bridge's messages over Cyclone DDS
// (ros/ros2/ros2_bench.h): 640x480 rgb8 and 32FC1 images at 30 Hz, Imu at 400 Hz and /tf at
// 500 Hz to a subscriber in another process, latency per message (median, p99) and samples lost
// per topic; a lockstep request -> frame + reply round trip. targets (docs/ros.md): added
// latency < 1 ms per frame, no message lost at the sensor-data QoS depth, round trip < 2 ms.
// a benchmark, never a pass/fail test: it prints numbers and targets.

#include "penumbra/ros/ros2/ros2_bench.h"

namespace penumbra {

/// runs the benchmark with `options`, prints its table to stdout; returns 0.
/// @throws Error on a bad option, when DDS cannot start, or when this build has no ROS 2.
int BenchRos2(const Ros2BenchOptions& options);

}  // namespace penumbra
