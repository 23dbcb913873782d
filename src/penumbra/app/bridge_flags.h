#pragma once
// the `penumbra run` flags of the middleware bridges (docs/zmq-protocol.md):
//   --zmq [ENDPOINT]      ZeroMQ bridge; default tcp://127.0.0.1:5555 (publish: port + 1)
//   --zmq-pub ENDPOINT    publish endpoint (default: the command endpoint's port + 1)
//   --bind ADDR           host of the tcp endpoints instead of loopback, e.g. 0.0.0.0
//   --ros [MASTER_URI]    ROS 1 bridge (docs/ros.md); default $ROS_MASTER_URI
//   --ros2                ROS 2 bridge over Cyclone DDS (docs/ros.md)
//   --ros-domain N        ROS 2 domain id, [0, 232]; default $ROS_DOMAIN_ID, else 0
//   --ros-interface ADDR  numeric address of the interface DDS uses; default 127.0.0.1
//   --ros-steps-per-trigger N  ROS 2: physics steps per /penumbra/step call (default 1)
//   --lockstep            start paused: the run advances only by `step` requests
//   --zmq-hwm N           send high-water mark per subscriber (messages, default 1000)
//   --zmq-max-request N   request size cap in bytes (default 1048576)
//   --zmq-state-hz HZ     rate of clock/joint_states/ground_truth/contacts (0 = every step)

#include <CLI/CLI.hpp>
#include <string>

#include "penumbra/run/runner.h"

namespace penumbra {

/// the bridge flags of `penumbra run` as given (see the file comment).
struct BridgeFlags {
  std::string zmq_endpoint;
  std::string zmq_pub;
  std::string bind;
  bool lockstep = false;
  std::string ros_master;  ///< --ros [MASTER_URI]
  bool ros2 = false;       ///< --ros2
  std::string ros_domain, ros_interface, ros_steps_per_trigger;
  std::string hwm, max_request, state_hz;

  /// adds the flags to the `run` subcommand.
  void Add(CLI::App* run);
  /// fills options->bridges and options->lockstep from the flags given on `run`.
  /// @throws ConfigError naming the flag for a bad value, --lockstep / --bind / --zmq-* without
  ///         --zmq, --ros-* without --ros2, --ros with --ros2.
  void Apply(const CLI::App& run, RunOptions* options) const;
};

}  // namespace penumbra
