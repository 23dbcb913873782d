#pragma once
// `penumbra bench bridge`: the cost of the ZeroMQ bridge (zmq/zmq_bridge.h, docs/zmq-protocol.md)
// on a real world, with a real client on tcp loopback in the same process:
//   1. lockstep round trip: `step` n=1 plus one 640x480 RGB frame published at that step,
//      send -> reply and frame received, median and p99, against the same `step` through the
//      command dispatcher in-process (no sockets, no frame): the difference is what the bridge
//      adds (target: < 1 ms median);
//   2. free-running: a pre-rendered 640x480 RGB frame published at every physics step, the
//      frames/s one subscriber receives (target: >= 300);
//   3. physics steps/s with the bridge attached and idle (no client) against no bridge, in
//      interleaved A/B rounds inside one process (target: ratio >= 0.95).
// a benchmark, never a pass/fail test: it prints numbers and the targets.

#include <memory>
#include <string>

namespace penumbra {

/// options of `penumbra bench bridge`.
struct BenchBridgeOptions {
  std::string world_file;     ///< world to step (default: worlds/quadruped.yaml)
  int trips = 500;            ///< lockstep round trips timed, >= 10
  double seconds = 3;         ///< wall seconds of the free-running measurement
  double round_seconds = 60;  ///< simulated seconds per physics A/B round
  int rounds = 5;             ///< A/B round pairs, >= 1
};

/// the verb as registered on `penumbra bench`.
/// runs the benchmark, prints its table to stdout; returns 0.
/// @throws ConfigError for a bad world; Error when no loopback port pair can be bound.
int BenchBridge(const BenchBridgeOptions& options);

}  // namespace penumbra
