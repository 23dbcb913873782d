#include "penumbra/ros/ros_bridge.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <map>
#include <mutex>

#include "penumbra/command/command_dispatcher.h"
#include "penumbra/control/controller_capabilities.h"
#include "penumbra/core/error.h"
#include "penumbra/ros/ros1_node.h"
#include "penumbra/ros/ros2/ros2_node.h"
#include "penumbra/ros/ros_convert.h"
#include "penumbra/ros/ros_graph.h"
#include "penumbra/world/adversity_preset.h"
#include "penumbra/world/ros_config.h"

namespace penumbra {

namespace {

using nlohmann::json;

// queue sizes per subscriber (roscpp drops the oldest message of a subscriber that falls behind)
constexpr int kImageQueue = 4;
constexpr int kSensorQueue = 100;
constexpr int kStateQueue = 20;
// /clock at most once per this much sim time
constexpr double kClockPeriodSec = 1e-3;
constexpr const char* kStepsPerTrigger = "/penumbra/steps_per_trigger";

std::unique_ptr<RosNode> MakeNode(const RosBridgeOptions& options) {
  if (options.transport == RosTransport::kRos2) {
    Ros2Node::Options o;
    o.name = options.node_name;
    o.domain_id = options.ros2_domain;
    o.interface_address = options.ros2_interface;
    return std::make_unique<Ros2Node>(o);
  }
  Ros1Node::Options o;
  o.name = options.node_name;
  o.master_uri = options.master_uri;
  return std::make_unique<Ros1Node>(o);
}

struct CameraTopics {
  const RosSensorGraph* graph = nullptr;
  int image = -1, info = -1, depth = -1, depth_info = -1;
};

class RosBridge : public RunBridge {
 public:
  RosBridge(const RunBridgeContext& context, const RosBridgeOptions& options)
      : context_(context),
        model_(context.session.sim().model_info()),
        options_(options),
        tag_(options.transport == RosTransport::kRos2 ? "ROS 2 bridge" : "ROS bridge") {
    Simulation& sim = context.session.sim();
    graph_ = BuildRosGraph(context.world, LoadRosConfig(context.world), model_,
                           SensorMountsOf(context.world, model_, context.session.scene()),
                           sim.MocapBodyNames());
    if (options.steps_per_trigger < 1)
      throw ConfigError("", 0, "--ros-steps-per-trigger",
                        fmt::format("{} is not a step count; expected an integer >= 1",
                                    options.steps_per_trigger));
    node_ = MakeNode(options);
    clock_ = node_->Advertise("/clock", RosTopicType::kClock, 10);
    tf_ = node_->Advertise("/tf", RosTopicType::kTf, kStateQueue);
    tf_static_ = node_->Advertise("/tf_static", RosTopicType::kTfStatic, 1);
    for (const RosRobotGraph& r : graph_.robots) {
      odom_.push_back(node_->Advertise(r.odom_topic, RosTopicType::kOdometry, kStateQueue));
      joint_states_.push_back(
          node_->Advertise(r.joint_states_topic, RosTopicType::kJointState, kStateQueue));
    }
    for (const RosSensorGraph& s : graph_.sensors) {
      switch (s.mount.kind) {
        case RosSensorKind::kCamera: {
          CameraTopics c;
          c.graph = &s;
          if (s.mount.rgb) {
            c.image = node_->Advertise(s.image_topic, RosTopicType::kImage, kImageQueue);
            c.info = node_->Advertise(s.info_topic, RosTopicType::kCameraInfo, kImageQueue);
          }
          if (s.mount.depth) {
            c.depth = node_->Advertise(s.depth_image_topic, RosTopicType::kImage, kImageQueue);
            c.depth_info =
                node_->Advertise(s.depth_info_topic, RosTopicType::kCameraInfo, kImageQueue);
          }
          cameras_[s.mount.name] = c;
          break;
        }
        case RosSensorKind::kLidar:
          sensors_[s.mount.name] = {
              &s, node_->Advertise(s.points_topic, RosTopicType::kPointCloud2, 4)};
          break;
        case RosSensorKind::kImu:
          sensors_[s.mount.name] = {
              &s, node_->Advertise(s.imu_topic, RosTopicType::kImu, kSensorQueue)};
          break;
      }
    }
    Subscribe();
    // callbacks run from now on: a lockstep run waits for its first request in the
    // RunControl's OnStart, which may come before this bridge's OnStart
    node_->Start();
    spdlog::info("{}: node /{} {}, {} topics (e.g. {})", tag_, options.node_name, node_->where(),
                 graph_.PublishedTopics().size(),
                 graph_.sensors.empty() ? std::string("/clock") : graph_.sensors.front().topic);
  }

  void OnStart(const LoopStart& start) override {
    next_state_k_ = static_cast<int64_t>(std::ceil(start.time_sec * graph_.state_rate_hz - 1e-9));
  }

  SnapshotContent Wants(int64_t step, double time_sec) override {
    if (last_clock_sec_ < 0 || time_sec - last_clock_sec_ >= kClockPeriodSec - 1e-12) {
      node_->PublishClock(clock_, RosStampNs(time_sec));
      last_clock_sec_ = time_sec;
    }
    if (time_sec + 1e-12 < static_cast<double>(next_state_k_) / graph_.state_rate_hz &&
        published_static_)
      return SnapshotContent::kNone;
    while (static_cast<double>(next_state_k_) / graph_.state_rate_hz <= time_sec + 1e-12)
      ++next_state_k_;
    state_step_ = step;
    return SnapshotContent::kFull;
  }

  void OnSnapshot(const std::shared_ptr<const WorldSnapshot>& snapshot) override {
    if (snapshot->step != state_step_ || snapshot->X_WB.empty()) return;
    if (!published_static_) {
      node_->Publish(tf_static_, StaticTransforms(graph_, *snapshot));
      published_static_ = true;
    }
    if (node_->Subscribers(tf_) > 0) node_->Publish(tf_, DynamicTransforms(graph_, *snapshot));
    const int64_t stamp = RosStampNs(snapshot->time_sec);
    for (size_t i = 0; i < graph_.robots.size(); ++i) {
      const RosRobotGraph& r = graph_.robots[i];
      if (node_->Subscribers(odom_[i]) > 0 && r.base_body < static_cast<int>(snapshot->V_WB.size()))
        node_->Publish(odom_[i],
                       OdometryToRos(snapshot->X_WB[r.base_body], snapshot->V_WB[r.base_body],
                                     r.odom_frame, r.base_frame, stamp));
      if (node_->Subscribers(joint_states_[i]) > 0)
        node_->Publish(joint_states_[i],
                       JointStateToRos(model_, r.joints, snapshot->qpos, snapshot->qvel,
                                       snapshot->qfrc_actuator, stamp));
    }
  }

  void OnCameraFrame(const std::shared_ptr<const CameraFrame>& frame) override {
    const auto it = cameras_.find(frame->camera);
    if (it == cameras_.end()) return;
    const CameraTopics& c = it->second;
    const RosHeader header = MakeRosHeader(frame->time_sec, c.graph->frame_id);
    const CameraIntrinsics& k = c.graph->mount.intrinsics;
    if (c.image >= 0 && !frame->rgb.empty() && node_->Subscribers(c.image) > 0)
      node_->Publish(c.image, RgbToRos(frame->rgb, header));
    if (c.info >= 0 && node_->Subscribers(c.info) > 0)
      node_->Publish(c.info, CameraInfoToRos(k, c.graph->mount.baseline_m, header));
    if (c.depth >= 0 && !frame->depth_m.empty() && node_->Subscribers(c.depth) > 0)
      node_->Publish(c.depth, DepthToRos(frame->depth_m, header));
    if (c.depth_info >= 0 && node_->Subscribers(c.depth_info) > 0)
      node_->Publish(c.depth_info, CameraInfoToRos(k, c.graph->mount.baseline_m, header));
  }

  void OnSensorSample(const SensorSample& sample) override {
    const auto it = sensors_.find(sample.sensor);
    if (it == sensors_.end() || node_->Subscribers(it->second.second) == 0) return;
    const RosSensorGraph& s = *it->second.first;
    const RosHeader header = MakeRosHeader(sample.time_sec, s.frame_id);
    if (sample.kind == SensorKind::kImu && sample.values.size() >= 6) {
      const Eigen::Vector3d accel(sample.values[0], sample.values[1], sample.values[2]);
      const Eigen::Vector3d gyro(sample.values[3], sample.values[4], sample.values[5]);
      node_->Publish(it->second.second,
                     ImuToRos(accel, gyro, s.mount.accel_noise_density, s.mount.gyro_noise_density,
                              s.mount.rate_hz, header));
    } else if (sample.kind == SensorKind::kLidar && sample.scan) {
      node_->Publish(it->second.second, PointsToRos(sample.scan->points, header));
    }
  }

 private:
  // sends a request; a failure is logged (topics have no reply channel)
  void Send(json request) {
    const std::string what = request.dump();
    context_.dispatcher.Dispatch(request, [what, tag = tag_](json reply) {
      if (!reply.value("ok", false))
        spdlog::warn("{}: {} was refused: {}", tag, what, reply.dump());
    });
  }

  // (success, message) of a request, for a Trigger service
  std::pair<bool, std::string> Call(const json& request) {
    const json reply = context_.dispatcher.Call(request);
    const bool ok = reply.value("ok", false);
    if (!ok) return {false, reply.dump()};
    std::string msg = reply.value("cmd", "");
    if (reply.contains("step") && reply.contains("time_sec"))
      msg += fmt::format(": step {}, t = {:.6f} s", reply["step"].get<int64_t>(),
                         reply["time_sec"].get<double>());
    else if (reply.contains("step"))
      msg += fmt::format(": step {}", reply["step"].get<int64_t>());
    return {true, msg};
  }

  void Subscribe() {
    Simulation& sim = context_.session.sim();
    for (const RosRobotGraph& r : graph_.robots) {
      const std::string robot = r.robot;
      node_->SubscribeTwist(r.cmd_vel_topic, [this, robot](const RosTwist& t) {
        Send({{"cmd", "twist"},
              {"robot", robot},
              {"vx", t.linear[0]},
              {"vy", t.linear[1]},
              {"yaw_rate", t.angular[2]}});
      });
      // the joint order of the robot's joint_pd controller, to map names
      std::vector<std::string> joints;
      for (int i = 0; i < sim.num_controllers(); ++i)
        if (const JointTarget* joint_target = AsJointTarget(sim.controller(i)))
          if (!joint_target->command_joints().empty() &&
              joint_target->command_joints().front().rfind(robot + "/", 0) == 0)
            joints = joint_target->command_joints();
      node_->SubscribeJointState(r.joint_commands_topic, [this, robot,
                                                          joints](const RosJointState& m) {
        const char* mode = !m.position.empty()   ? "position"
                           : !m.velocity.empty() ? "velocity"
                                                 : "effort";
        const std::vector<double>& v =
            !m.position.empty() ? m.position : (!m.velocity.empty() ? m.velocity : m.effort);
        std::vector<double> values = v;
        if (!m.name.empty() && !joints.empty()) {
          if (m.name.size() != v.size()) {
            spdlog::warn("{}: joint command for '{}' with {} names and {} values", tag_, robot,
                         m.name.size(), v.size());
            return;
          }
          // which joints were named: a NaN value goes on to the dispatcher, which refuses it
          std::vector<bool> named(joints.size(), false);
          values.assign(joints.size(), 0.0);
          for (size_t i = 0; i < m.name.size(); ++i) {
            auto it = std::find_if(joints.begin(), joints.end(), [&](const std::string& j) {
              return j == m.name[i] || j == robot + "/" + m.name[i];
            });
            if (it == joints.end()) {
              spdlog::warn(
                  "{}: joint command for '{}' names joint '{}', which its controller does not "
                  "drive",
                  tag_, robot, m.name[i]);
              return;
            }
            values[it - joints.begin()] = v[i];
            named[it - joints.begin()] = true;
          }
          if (std::find(named.begin(), named.end(), false) != named.end()) {
            spdlog::warn("{}: joint command for '{}' does not name every joint of its controller",
                         tag_, robot);
            return;
          }
        }
        Send({{"cmd", "joint_targets"}, {"robot", robot}, {"mode", mode}, {"values", values}});
      });
    }
    for (size_t i = 0; i < graph_.mocap_bodies.size(); ++i) {
      const std::string body = graph_.mocap_bodies[i];
      node_->SubscribePose(graph_.mocap_topics[i], [this, body](const RosPoseStamped& p) {
        Send({{"cmd", "set_mocap"},
              {"body", body},
              {"xyz", {p.position[0], p.position[1], p.position[2]}},
              {"qwxyz", {p.orientation[3], p.orientation[0], p.orientation[1], p.orientation[2]}}});
      });
    }
    // ROS 1 keeps a value already on the parameter server; ROS 2 has no parameter server
    if (options_.transport == RosTransport::kRos2)
      node_->SetParam(kStepsPerTrigger, options_.steps_per_trigger);
    else
      node_->SetParam(kStepsPerTrigger, node_->IntParam(kStepsPerTrigger, 1));
    node_->AdvertiseTrigger("/penumbra/step", [this] {
      const int64_t n = node_->IntParam(kStepsPerTrigger, 1);
      return Call({{"cmd", "step"}, {"n", n}});
    });
    node_->AdvertiseTrigger("/penumbra/pause", [this] { return Call({{"cmd", "pause"}}); });
    node_->AdvertiseTrigger("/penumbra/resume", [this] { return Call({{"cmd", "resume"}}); });
    node_->AdvertiseTrigger("/penumbra/reset", [this] { return Call({{"cmd", "reset"}}); });
    for (const std::string& preset : BundledAdversityPresetNames())
      node_->AdvertiseTrigger("/penumbra/adversity/" + preset, [this, preset] {
        return Call({{"cmd", "set_adversity"}, {"preset", preset}});
      });
  }

  RunBridgeContext context_;
  const ModelInfo& model_;
  RosBridgeOptions options_;
  std::string tag_;  // "ROS bridge" / "ROS 2 bridge", for the log
  RosGraph graph_;
  std::unique_ptr<RosNode> node_;
  int clock_ = -1, tf_ = -1, tf_static_ = -1;
  std::vector<int> odom_, joint_states_;
  std::map<std::string, CameraTopics> cameras_;
  std::map<std::string, std::pair<const RosSensorGraph*, int>> sensors_;
  double last_clock_sec_ = -1;
  int64_t next_state_k_ = 0;
  int64_t state_step_ = -1;
  bool published_static_ = false;
};

}  // namespace

RunBridgeFactory MakeRosBridgeFactory(RosBridgeOptions options) {
  return [options](const RunBridgeContext& context) -> std::unique_ptr<RunBridge> {
    return std::make_unique<RosBridge>(context, options);
  };
}

}  // namespace penumbra
