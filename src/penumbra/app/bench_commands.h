#pragma once
// the `penumbra bench` verbs whose harnesses live in bench/ (throughput and latency
// benchmarks, never pass/fail tests; docs/benchmarks.md, docs/performance.md):
//   bench render    frames/s and Mrays/s (bench/bench.h BenchRender)
//   bench physics   physics steps/s vs a bare mj_step loop (BenchPhysics)
//   bench record    run-log recording on vs off (bench/record/bench_record.h)
//   bench bridge    the ZeroMQ bridge (bench/net/bench_bridge.h)
//   bench ros       the ROS 1 transport (bench/net/bench_ros.h)
//   bench ros2      the ROS 2 transport over Cyclone DDS (bench/net/bench_ros2.h)
//   bench sensors   LiDAR rays/s, IMU/MuJoCo sensor overhead (bench/sensors/sensor_bench.h)
// (the `bench decompose` and `bench viewer` verbs are in app/decompose_command.h and
// app/viewer_commands.h, beside `decompose` and `view`; their harnesses are in bench/ too.)

#include <memory>

#include "penumbra/app/command.h"

namespace penumbra {

std::unique_ptr<Command> MakeBenchRenderCommand();
std::unique_ptr<Command> MakeBenchPhysicsCommand();
std::unique_ptr<Command> MakeBenchRecordCommand();
std::unique_ptr<Command> MakeBenchBridgeCommand();
std::unique_ptr<Command> MakeBenchRosCommand();
std::unique_ptr<Command> MakeBenchRos2Command();
std::unique_ptr<Command> MakeBenchSensorsCommand();

}  // namespace penumbra
