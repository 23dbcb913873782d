#pragma once
// `penumbra bench ros [--seconds S] [--trips N] [--master URI]`: the ROS 1 transport cost of the
// bridge's images (ros/ros_bench.h): round trip of one 640x480 rgb8 frame to a subscriber in
// another process and back, median and p99, and the frames/s a subscriber receives from a
// publisher sending pre-rendered frames back to back (target: >= 100). needs a running master
// (roscore; ROS_MASTER_URI). a benchmark, never a pass/fail test: it prints numbers and targets.

#include "penumbra/ros/ros_bench.h"

namespace penumbra {

/// runs the benchmark with `options`, prints its table to stdout; returns 0.
/// @throws Error when no master answers or this build has no ROS 1.
int BenchRos(const RosBenchOptions& options);

}  // namespace penumbra
