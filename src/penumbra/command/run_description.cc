#include "penumbra/command/run_description.h"

#include <Eigen/Geometry>

#include "penumbra/control/controller_capabilities.h"
#include "penumbra/control/joint_type_name.h"

namespace penumbra {

std::string ControllerRobot(const Controller& controller) {
  const std::string& key = controller.context().key;
  const std::string prefix = "robots[";
  if (key.rfind(prefix, 0) != 0) return "";
  const size_t end = key.find("].controller");
  if (end == std::string::npos) return "";
  return key.substr(prefix.size(), end - prefix.size());
}

nlohmann::json DescribeRun(Session& session, const WorldConfig& world) {
  using json = nlohmann::json;
  const Simulation& sim = session.sim();
  const ModelInfo& mi = sim.model_info();
  json j;
  j["timestep_sec"] = sim.timestep();
  j["nq"] = mi.nq;
  j["nv"] = mi.nv;
  j["nu"] = mi.nu;
  j["nsensordata"] = mi.nsensordata;
  j["seed"] = world.seed;
  j["end_time_sec"] = world.duration_sec;

  json bodies = json::array();
  for (size_t b = 0; b < mi.body_names.size(); ++b)
    bodies.push_back({{"id", b},
                      {"name", mi.body_names[b]},
                      {"parent", b < mi.body_parent.size() ? mi.body_parent[b] : -1}});
  j["bodies"] = std::move(bodies);

  json joints = json::array();
  for (size_t i = 0; i < mi.joints.size(); ++i) {
    const JointInfo& jt = mi.joints[i];
    joints.push_back({{"id", i},
                      {"name", jt.name},
                      {"type", JointTypeName(jt.type)},
                      {"body", jt.body},
                      {"qpos_adr", jt.qpos_adr},
                      {"dof_adr", jt.dof_adr},
                      {"limited", jt.limited},
                      {"range", {jt.range[0], jt.range[1]}}});
  }
  j["joints"] = std::move(joints);

  json actuators = json::array();
  for (size_t i = 0; i < mi.actuators.size(); ++i) {
    const ActuatorInfo& a = mi.actuators[i];
    actuators.push_back({{"id", i},
                         {"name", a.name},
                         {"joint", a.joint},
                         {"ctrl_limited", a.ctrl_limited},
                         {"ctrl_range", {a.ctrl_range[0], a.ctrl_range[1]}}});
  }
  j["actuators"] = std::move(actuators);

  json sensors = json::array();
  for (size_t i = 0; i < mi.sensors.size(); ++i)
    sensors.push_back({{"id", i},
                       {"name", mi.sensors[i].name},
                       {"adr", mi.sensors[i].adr},
                       {"dim", mi.sensors[i].dim}});
  j["mujoco_sensors"] = std::move(sensors);

  json mocap = json::array();
  const std::vector<std::string> mocap_names = sim.MocapBodyNames();
  for (size_t i = 0; i < mocap_names.size(); ++i)
    mocap.push_back(
        {{"id", i}, {"name", mocap_names[i]}, {"driven", sim.MocapDriven(static_cast<int>(i))}});
  j["nmocap"] = mocap_names.size();
  j["mocap_bodies"] = std::move(mocap);

  json keys = json::array();
  for (const KeyInfo& k : mi.keys) keys.push_back(k.name);
  j["keyframes"] = std::move(keys);

  json cameras = json::array();
  for (const CameraSpec& c : session.scene().cameras) {
    json outputs = json::array();
    for (const ImageKindInfo& k : kImageKinds)
      if (c.outputs[k.kind]) outputs.push_back(std::string(k.name));
    const CameraIntrinsics& in = c.intrinsics;
    cameras.push_back({{"name", c.name},
                       {"width", in.width},
                       {"height", in.height},
                       {"fx", in.fx},
                       {"fy", in.fy},
                       {"cx", in.cx},
                       {"cy", in.cy},
                       {"distortion", {in.k1, in.k2, in.p1, in.p2, in.k3}},
                       {"rate_hz", c.rate_hz},
                       {"frame_id", c.name + "/optical"},
                       {"outputs", std::move(outputs)}});
  }
  j["cameras"] = std::move(cameras);

  json world_sensors = json::array();
  for (const SensorConfig& s : world.sensors) {
    // the type's default rate; a LiDAR's comes from its preset (null here)
    const SensorTypeInfo& type = Info(s.kind());
    json rate = nullptr;
    if (s.rate_hz)
      rate = *s.rate_hz;
    else if (!type.rate_from_model)
      rate = type.default_rate_hz;
    world_sensors.push_back(
        {{"name", s.name},
         {"type", std::string(type.name)},
         {"rate_hz", rate},
         {"frame_id", type.attach == SensorAttach::kNone ? std::string("world") : s.name}});
  }
  j["sensors"] = std::move(world_sensors);

  json controllers = json::array();
  for (int i = 0; i < sim.num_controllers(); ++i) {
    const Controller& c = sim.controller(i);
    controllers.push_back({{"index", i},
                           {"robot", ControllerRobot(c)},
                           {"type", c.type()},
                           {"commands", ControllerCommands(c)}});
  }
  j["controllers"] = std::move(controllers);
  return j;
}

}  // namespace penumbra
