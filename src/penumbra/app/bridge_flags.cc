#include "penumbra/app/bridge_flags.h"

#include <fmt/format.h>

#include <charconv>
#include <cstdlib>

#include "penumbra/core/error.h"
#include "penumbra/core/text_match.h"
#include "penumbra/ros/ros2_names.h"
#include "penumbra/ros/ros_bridge.h"
#include "penumbra/zmq/zmq_bridge.h"

namespace penumbra {
namespace {

int64_t ParseCount(const std::string& flag, const std::string& s, int64_t lo, int64_t hi) {
  int64_t v = 0;
  const auto r = std::from_chars(s.data(), s.data() + s.size(), v);
  if (s.empty() || r.ec != std::errc() || r.ptr != s.data() + s.size() || v < lo || v > hi)
    throw ConfigError("", 0, flag, fmt::format("'{}' is not an integer in [{}, {}]", s, lo, hi));
  return v;
}

}  // namespace

void BridgeFlags::Add(CLI::App* run) {
  run->add_option("--zmq", zmq_endpoint,
                  "serve the run over ZeroMQ (docs/zmq-protocol.md): commands on ENDPOINT "
                  "(default tcp://127.0.0.1:5555), sensors published on its port + 1")
      ->expected(0, 1)
      ->type_name("[ENDPOINT]");
  run->add_option("--zmq-pub", zmq_pub, "ZeroMQ publish endpoint (default: command port + 1)");
  run->add_option("--bind", bind, "host the bridges bind to instead of loopback (e.g. 0.0.0.0)");
  run->add_option("--ros", ros_master,
                  "serve the run over ROS 1 (docs/ros.md): topics, tf, /clock, cmd_vel and the "
                  "/penumbra/step service; the master at MASTER_URI (default $ROS_MASTER_URI)")
      ->expected(0, 1)
      ->type_name("[MASTER_URI]");
  run->add_flag("--ros2", ros2,
                "serve the run over ROS 2 (docs/ros.md): the same topics, tf, /clock, cmd_vel and "
                "/penumbra/* services as --ros, on DDS (Cyclone DDS, as rmw_cyclonedds_cpp) in "
                "the domain of --ros-domain, on the interface of --ros-interface");
  run->add_option("--ros-domain", ros_domain,
                  "with --ros2: the ROS 2 domain id, 0 to 232 (default $ROS_DOMAIN_ID, else 0)")
      ->type_name("N");
  run->add_option("--ros-interface", ros_interface,
                  "with --ros2: numeric address of the one network interface DDS uses (default "
                  "127.0.0.1: this machine only, as ROS_LOCALHOST_ONLY=1)")
      ->type_name("ADDR");
  run->add_option("--ros-steps-per-trigger", ros_steps_per_trigger,
                  "with --ros2: physics steps per /penumbra/step call (default 1)")
      ->type_name("N");
  run->add_flag("--lockstep", lockstep,
                "with --zmq, --ros, --ros2 or --viewer: start paused; the run advances only by "
                "`step` requests");
  run->add_option("--zmq-hwm", hwm, "ZeroMQ send high-water mark per subscriber (default 1000)");
  run->add_option("--zmq-max-request", max_request, "largest request in bytes (default 1048576)");
  run->add_option("--zmq-state-hz", state_hz,
                  "rate of the clock/joint_states/ground_truth/contacts topics, Hz of sim time "
                  "(default 0: every physics step)");
}

void BridgeFlags::Apply(const CLI::App& run, RunOptions* options) const {
  const bool zmq = run.count("--zmq") > 0;
  const bool ros = run.count("--ros") > 0;
  const bool ros2_on = run.count("--ros2") > 0;
  if (ros && ros2_on)
    throw ConfigError("", 0, "--ros2",
                      "--ros (ROS 1) and --ros2 (ROS 2) both given; a run serves one ROS (bridge "
                      "ROS 1 to ROS 2 with ros1_bridge if both are needed)");
  // the live viewer (app/viewer_commands.h) is a bridge too: --lockstep works with it
  const CLI::Option* viewer_flag = run.get_option_no_throw("--viewer");
  const bool viewer = viewer_flag && viewer_flag->count() > 0;
  if (run.count("--lockstep") > 0 && !zmq && !ros && !ros2_on && !viewer)
    throw ConfigError("", 0, "--lockstep",
                      "needs --zmq, --ros, --ros2 or --viewer (a bridge to serve the run)");
  for (const char* flag : {"--ros-domain", "--ros-interface", "--ros-steps-per-trigger"})
    if (run.count(flag) > 0 && !ros2_on)
      throw ConfigError("", 0, flag, "needs --ros2 (the ROS 2 bridge)");
  for (const char* flag :
       {"--zmq-pub", "--bind", "--zmq-hwm", "--zmq-max-request", "--zmq-state-hz"})
    if (run.count(flag) > 0 && !zmq)
      throw ConfigError("", 0, flag, "needs --zmq (a bridge to serve the run)");
  if (ros) {
    RosBridgeOptions r;
    r.master_uri = ros_master;
    options->bridges.push_back(MakeRosBridgeFactory(r));
  }
  if (ros2_on) {
    RosBridgeOptions r;
    r.transport = RosTransport::kRos2;
    r.ros2_domain = Ros2DomainId(ros_domain, std::getenv("ROS_DOMAIN_ID"));
    if (!ros_interface.empty()) r.ros2_interface = CheckInterfaceAddress(ros_interface);
    if (!ros_steps_per_trigger.empty())
      r.steps_per_trigger =
          ParseCount("--ros-steps-per-trigger", ros_steps_per_trigger, 1, 1000000);
    options->bridges.push_back(MakeRosBridgeFactory(r));
  }
  if (!zmq) {
    options->lockstep = lockstep;
    return;
  }
  ZmqBridgeOptions o;
  if (!zmq_endpoint.empty()) o.endpoint = zmq_endpoint;
  o.pub_endpoint = zmq_pub;
  o.bind = bind;
  if (!hwm.empty()) o.hwm = static_cast<int>(ParseCount("--zmq-hwm", hwm, 1, 1 << 30));
  if (!max_request.empty())
    o.max_request_bytes = ParseCount("--zmq-max-request", max_request, 64, 64ll << 20);
  if (!state_hz.empty()) {
    const std::optional<double> v = ParseDecimal(state_hz);
    if (!v || !(*v >= 0))
      throw ConfigError("", 0, "--zmq-state-hz",
                        fmt::format("'{}' is not a rate; expected Hz >= 0", state_hz));
    o.state_hz = *v;
  }
  options->bridges.push_back(MakeZmqBridgeFactory(o));
  options->lockstep = lockstep;
}

}  // namespace penumbra
