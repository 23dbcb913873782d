#include "penumbra/ros/ros_graph.h"

#include <algorithm>
#include <cctype>
#include <map>

#include "penumbra/core/error.h"
#include "penumbra/sensors/imu_model.h"
#include "penumbra/world/ros_config.h"

namespace penumbra {

namespace {

const RosRobotConfig* FindRobotConfig(const RosConfig& c, const std::string& robot) {
  for (const RosRobotConfig& r : c.robots)
    if (r.robot == robot) return &r;
  return nullptr;
}

const RosSensorConfig* FindSensorConfig(const RosConfig& c, const std::string& sensor) {
  for (const RosSensorConfig& s : c.sensors)
    if (s.sensor == sensor) return &s;
  return nullptr;
}

// the model name of a composed name "<model>/<rest>", or ""
std::string ModelOf(const std::string& composed) {
  const size_t slash = composed.find('/');
  return slash == std::string::npos ? "" : composed.substr(0, slash);
}

// the controller's `base_body` parameter (model-local), or ""
std::string ControllerBaseBody(const ModelConfig& m) {
  const ConfigValue& p = m.controller.params;
  if (!p || !p.IsMap()) return "";
  const ConfigValue b = p["base_body"];
  return b && b.IsScalar() ? b.Scalar() : "";
}

}  // namespace

std::string RosNameOf(const std::string& world_name) {
  std::string out;
  bool segment_start = true;
  for (char ch : world_name) {
    const unsigned char c = static_cast<unsigned char>(ch);
    if (c == '/') {
      if (!segment_start) out += '/';
      segment_start = true;
      continue;
    }
    if (segment_start && std::isdigit(c)) out += '_';
    out += std::isalnum(c) ? ch : '_';
    segment_start = false;
  }
  while (!out.empty() && out.back() == '/') out.pop_back();
  return out;
}

std::string JoinRosName(const std::string& ns, const std::string& name) {
  if (!name.empty() && name[0] == '/') return name;
  std::string base = ns;
  while (!base.empty() && base.back() == '/') base.pop_back();
  if (!base.empty() && base[0] != '/') base = "/" + base;
  return base + "/" + name;
}

int RigidBodyOf(const ModelInfo& model, int b, const std::vector<std::string>& mocap_bodies) {
  while (b > 0) {
    const bool jointed = std::any_of(model.joints.begin(), model.joints.end(),
                                     [b](const JointInfo& j) { return j.body == b; });
    const bool mocap = std::find(mocap_bodies.begin(), mocap_bodies.end(), model.body_names[b]) !=
                       mocap_bodies.end();
    if (jointed || mocap) return b;
    b = model.body_parent[b];
  }
  return 0;
}

const RosSensorGraph* RosGraph::FindSensor(const std::string& name) const {
  for (const RosSensorGraph& s : sensors)
    if (s.mount.name == name) return &s;
  return nullptr;
}

std::vector<std::string> RosGraph::PublishedTopics() const {
  std::vector<std::string> t = {"/clock", "/tf", "/tf_static"};
  for (const RosRobotGraph& r : robots) {
    t.push_back(r.odom_topic);
    t.push_back(r.joint_states_topic);
  }
  for (const RosSensorGraph& s : sensors) {
    switch (s.mount.kind) {
      case RosSensorKind::kCamera:
        if (s.mount.rgb) {
          t.push_back(s.image_topic);
          t.push_back(s.info_topic);
        }
        if (s.mount.depth) {
          t.push_back(s.depth_image_topic);
          t.push_back(s.depth_info_topic);
        }
        break;
      case RosSensorKind::kLidar:
        t.push_back(s.points_topic);
        break;
      case RosSensorKind::kImu:
        t.push_back(s.imu_topic);
        break;
    }
  }
  std::sort(t.begin(), t.end());
  return t;
}

RosGraph BuildRosGraph(const WorldConfig& world, const RosConfig& cfg, const ModelInfo& model,
                       const std::vector<RosSensorMount>& sensors,
                       const std::vector<std::string>& mocap_bodies) {
  RosGraph g;
  g.map_frame = cfg.map_frame;
  g.state_rate_hz = cfg.state_rate_hz;
  const std::string ns = cfg.ns == "/" ? "" : cfg.ns;
  int robot_count = 0;
  for (const ModelConfig& m : world.models) robot_count += m.is_robot ? 1 : 0;

  std::map<std::string, int> robot_index;  // model name -> robots index
  for (const ModelConfig& m : world.models) {
    if (!m.is_robot) continue;
    const RosRobotConfig* rc = FindRobotConfig(cfg, m.name);
    RosRobotGraph r;
    r.robot = m.name;
    // base body: the override, the controller's base_body, else the model's first body
    std::string base = rc && !rc->base_body.empty() ? rc->base_body : ControllerBaseBody(m);
    if (!base.empty()) {
      r.base_body = model.Find(ModelObject::kBody, m.name + "/" + base);
      if (r.base_body < 0)
        throw ConfigError("", 0,
                          rc && !rc->base_body.empty() ? "ros.robots." + m.name + ".base_body"
                                                       : "ros.robots." + m.name,
                          "robot '" + m.name + "' has no body '" + base +
                              "'; expected a body of the model (without the \"" + m.name +
                              "/\" prefix)");
    } else {
      r.base_body = -1;
      for (size_t b = 1; b < model.body_names.size(); ++b)
        if (ModelOf(model.body_names[b]) == m.name) {
          r.base_body = static_cast<int>(b);
          break;
        }
      if (r.base_body < 0)
        throw ConfigError("", 0, "ros.robots." + m.name,
                          "robot '" + m.name + "' has no body in the composed model");
    }
    const std::string prefix = robot_count > 1 ? m.name + "/" : "";
    r.base_frame = rc && !rc->base_frame.empty() ? rc->base_frame : prefix + "base_link";
    r.odom_frame = rc && !rc->odom_frame.empty() ? rc->odom_frame : prefix + "odom";
    const std::string robot_ns =
        JoinRosName(ns, rc && !rc->ns.empty() ? rc->ns : RosNameOf(m.name));
    r.odom_topic = JoinRosName(robot_ns, "odom");
    r.joint_states_topic = JoinRosName(robot_ns, "joint_states");
    r.cmd_vel_topic = JoinRosName(robot_ns, "cmd_vel");
    r.joint_commands_topic = JoinRosName(robot_ns, "joint_commands");
    for (size_t j = 0; j < model.joints.size(); ++j) {
      const JointInfo& ji = model.joints[j];
      if ((ji.type == JointInfo::Type::kHinge || ji.type == JointInfo::Type::kSlide) &&
          ModelOf(ji.name) == m.name)
        r.joints.push_back(static_cast<int>(j));
    }
    robot_index[m.name] = static_cast<int>(g.robots.size());
    g.robots.push_back(r);
  }

  for (const RosSensorMount& mount : sensors) {
    RosSensorGraph s;
    s.mount = mount;
    const std::string owner = mount.body < 0
                                  ? ModelOf(mount.name)
                                  : (mount.body == 0 ? "" : ModelOf(model.body_names[mount.body]));
    if (auto it = robot_index.find(owner); it != robot_index.end()) s.robot = it->second;
    const RosSensorConfig* sc = FindSensorConfig(cfg, mount.name);
    std::string base_ns = ns;
    if (s.robot >= 0) {
      const RosRobotConfig* rc = FindRobotConfig(cfg, g.robots[s.robot].robot);
      base_ns = JoinRosName(ns, rc && !rc->ns.empty() ? rc->ns : RosNameOf(owner));
    }
    // an MJCF camera "<model>/<camera>" under its robot's namespace is "<camera>" there
    std::string local = mount.name;
    if (s.robot >= 0 && mount.body < 0) local = mount.name.substr(owner.size() + 1);
    s.topic = JoinRosName(base_ns, sc && !sc->topic.empty() ? sc->topic : RosNameOf(local));
    const bool camera = mount.kind == RosSensorKind::kCamera;
    s.frame_id = sc && !sc->frame_id.empty() ? sc->frame_id
                                             : (camera ? mount.name + "/optical" : mount.name);
    s.parent_frame = s.robot >= 0 ? g.robots[s.robot].base_frame : g.map_frame;
    if (mount.body >= 0) {
      const int rigid = RigidBodyOf(model, mount.body, mocap_bodies);
      s.rigid_to_parent =
          s.robot >= 0 ? rigid == RigidBodyOf(model, g.robots[s.robot].base_body, mocap_bodies)
                       : rigid == 0;
    }
    switch (mount.kind) {
      case RosSensorKind::kCamera:
        s.image_topic = s.topic + "/image_raw";
        s.info_topic = s.topic + "/camera_info";
        s.depth_image_topic = s.topic + "/depth/image_raw";
        s.depth_info_topic = s.topic + "/depth/camera_info";
        break;
      case RosSensorKind::kLidar:
        s.points_topic = s.topic + "/points";
        break;
      case RosSensorKind::kImu:
        s.imu_topic = s.topic + "/data";
        break;
    }
    g.sensors.push_back(s);
  }
  // MJCF-camera overrides name cameras known only now
  for (const RosSensorConfig& sc : cfg.sensors)
    if (!g.FindSensor(sc.sensor)) {
      std::string names;
      for (const RosSensorGraph& s : g.sensors) names += (names.empty() ? "" : ", ") + s.mount.name;
      throw ConfigError("", 0, "ros.sensors." + sc.sensor,
                        "'" + sc.sensor +
                            "' is not a camera, LiDAR or IMU of the world; expected one of: " +
                            (names.empty() ? std::string("(none)") : names));
    }
  for (const std::string& body : mocap_bodies) {
    g.mocap_bodies.push_back(body);
    g.mocap_topics.push_back(JoinRosName(JoinRosName(ns, "mocap"), RosNameOf(body) + "/pose"));
  }

  // no two owners may share a topic or a frame
  std::map<std::string, std::string> topics, frames;
  auto claim = [](std::map<std::string, std::string>& seen, const std::string& name,
                  const std::string& owner, const char* what) {
    if (name.empty()) return;
    auto [it, fresh] = seen.emplace(name, owner);
    if (!fresh && it->second != owner)
      throw ConfigError("", 0, "ros",
                        std::string(what) + " '" + name + "' is used by both " + it->second +
                            " and " + owner + "; expected distinct names (set them in ros:)");
  };
  claim(frames, g.map_frame, "the map frame", "frame");
  for (const RosRobotGraph& r : g.robots) {
    const std::string owner = "robot '" + r.robot + "'";
    claim(frames, r.base_frame, owner, "frame");
    claim(frames, r.odom_frame, owner + " (odom)", "frame");
    for (const std::string* t :
         {&r.odom_topic, &r.joint_states_topic, &r.cmd_vel_topic, &r.joint_commands_topic})
      claim(topics, *t, owner, "topic");
  }
  for (const RosSensorGraph& s : g.sensors) {
    const std::string owner = "sensor '" + s.mount.name + "'";
    claim(frames, s.frame_id, owner, "frame");
    for (const std::string* t : {&s.image_topic, &s.info_topic, &s.depth_image_topic,
                                 &s.depth_info_topic, &s.points_topic, &s.imu_topic})
      claim(topics, *t, owner, "topic");
  }
  for (size_t i = 0; i < g.mocap_topics.size(); ++i)
    claim(topics, g.mocap_topics[i], "mocap body '" + g.mocap_bodies[i] + "'", "topic");
  return g;
}

std::vector<RosSensorMount> SensorMountsOf(const WorldConfig& world, const ModelInfo& model,
                                           const SceneDescription& scene) {
  std::vector<RosSensorMount> out;
  for (const CameraSpec& c : scene.cameras) {
    RosSensorMount m;
    m.name = c.name;
    m.kind = RosSensorKind::kCamera;
    m.body = c.mjcf_camera >= 0 ? -1 : c.body;
    m.mjcf_camera = c.mjcf_camera;
    m.X_BS = c.X_BO;
    m.intrinsics = c.intrinsics;
    m.rgb = c.outputs.rgb;
    m.depth = c.outputs.depth;
    out.push_back(m);
  }
  for (const SensorConfig& sc : world.sensors) {
    if (sc.type != "lidar" && sc.type != "imu") continue;
    RosSensorMount m;
    m.name = sc.name;
    m.kind = sc.type == "lidar" ? RosSensorKind::kLidar : RosSensorKind::kImu;
    Pose X_BA = Pose::Identity();
    if (!sc.site.empty()) {
      const int site = model.Find(ModelObject::kSite, sc.site);
      if (site < 0)
        throw ConfigError(sc.file, sc.line, sc.key + ".site",
                          "no site '" + sc.site + "' in the composed model");
      m.body = model.site_body[site];
      X_BA = model.site_X_BS[site];
    } else if (sc.body == "world" || sc.body.empty()) {
      m.body = 0;
    } else {
      m.body = model.Find(ModelObject::kBody, sc.body);
      if (m.body < 0)
        throw ConfigError(sc.file, sc.line, sc.key + ".body",
                          "no body '" + sc.body + "' in the composed model");
    }
    m.X_BS = X_BA * sc.X_AS();
    if (m.kind == RosSensorKind::kImu) {
      m.rate_hz = sc.rate_hz.value_or(200);
      const ImuNoiseConfig nc = ImuPreset(sc.preset);
      m.accel_noise_density = sc.Param("noise.accel_noise_density", nc.accel_noise_density);
      m.gyro_noise_density = sc.Param("noise.gyro_noise_density", nc.gyro_noise_density);
    }
    out.push_back(m);
  }
  return out;
}

}  // namespace penumbra
