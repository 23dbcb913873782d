#include "penumbra/live/run_log_header.h"

#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

#include "penumbra/compose/mjcf_assets.h"
#include "penumbra/control/joint_type_name.h"
#include "penumbra/physics/mujoco_version.h"

namespace penumbra {
namespace {

std::string ReadText(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(path + ": cannot be read for the run log header");
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

std::string Absolute(const std::string& path) {
  std::error_code ec;
  const std::filesystem::path p = std::filesystem::absolute(path, ec);
  return ec ? path : p.lexically_normal().string();
}

}  // namespace

RunLogLayout RunLogLayoutOf(const Simulation& sim) {
  // the SimState sizes and the names that map them
  const ModelInfo& info = sim.model_info();
  const SimState state = sim.GetState();
  RunLogLayout l;
  l.set_dims(StateDimsOf(state));
  for (const JointInfo& j : info.joints) {
    RunLogJoint x;
    x.name = j.name;
    x.type = JointTypeName(j.type);
    x.qpos_adr = j.qpos_adr;
    x.qvel_adr = j.dof_adr;
    x.qpos_width = j.type == JointInfo::Type::kFree ? 7 : j.type == JointInfo::Type::kBall ? 4 : 1;
    x.qvel_width = j.type == JointInfo::Type::kFree ? 6 : j.type == JointInfo::Type::kBall ? 3 : 1;
    l.joints.push_back(std::move(x));
  }
  for (const ActuatorInfo& a : info.actuators) l.actuator_names.push_back(a.name);
  l.mocap_body_names = sim.MocapBodyNames();
  l.body_names = info.body_names;
  for (int i = 0; i < sim.num_controllers(); ++i)
    l.controller_names.push_back(sim.controller(i).type());
  return l;
}

RunLogHeader MakeRunLogHeader(const Session& session, const std::string& penumbra_version,
                              const std::string& command_line) {
  const WorldConfig& world = session.world();
  const Simulation& sim = session.sim();
  RunLogHeader h;
  h.penumbra_version = penumbra_version;
  h.mujoco_version = MujocoVersion();
  if (!world.file.empty()) {
    h.world_file = Absolute(world.file);
    h.world_text = ReadText(world.file);
  } else if (!world.models.empty()) {
    h.model_file = Absolute(world.models.front().file);
    h.model_text = ReadText(world.models.front().file);
  }
  h.composed_mjcf = session.composed_xml();
  h.seed = world.seed;
  h.command_line = command_line;
  h.timestep_sec = sim.timestep();
  h.adversity = session.effects().PresetLabel();

  // every file read, each once
  std::set<std::string> seen;
  const auto hash = [&](const std::string& role, const std::string& path) {
    const std::string abs = Absolute(path);
    if (!seen.insert(abs).second) return;
    RunLogAsset a;
    a.role = role;
    a.path = abs;
    try {
      a.sha256 = Sha256OfFile(abs, &a.size_bytes);
    } catch (const RunLogError&) {
      a.sha256.clear();
    }
    h.assets.push_back(std::move(a));
  };
  if (!world.file.empty()) hash("world", world.file);
  for (const ModelConfig& m : world.models) hash("model", m.file);
  if (!world.adversity.empty() && std::filesystem::is_regular_file(world.adversity))
    hash("adversity", world.adversity);
  for (const MjcfAssetFile& f : MjcfAssetFiles(session.composed_xml())) hash(f.role, f.path);

  h.layout = RunLogLayoutOf(sim);
  return h;
}

}  // namespace penumbra
