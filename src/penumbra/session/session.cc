#include "penumbra/session/session.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <csignal>
#include <filesystem>
#include <functional>

#include "penumbra/compose/imu_injection.h"
#include "penumbra/compose/scene_composer.h"
#include "penumbra/control/controller_capabilities.h"
#include "penumbra/control/controller_factory.h"
#include "penumbra/core/error.h"
#include "penumbra/core/output_file.h"
#include "penumbra/environment/model_sources.h"
#include "penumbra/physics/urdf_converter.h"
#include "penumbra/render/backends/renderer_factory.h"
#include "penumbra/session/scene_assembly.h"
#include "penumbra/session/static_terrain_ray_caster.h"
#include "penumbra/session/world_composer.h"
#include "penumbra/world/run_budget.h"

namespace penumbra {
namespace {

using Clock = std::chrono::steady_clock;

double SecondsSince(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

const char* SignalName(int sig) {
  return sig == SIGTERM ? "SIGTERM" : sig == SIGINT ? "SIGINT" : "a signal";
}

// what the settle may move: the free joints (floating bases) of robots driven by trot_gait and
// the joints below them. trot_gait holds its stance when reset at every step (its references
// are the pose it finds, its stance forces carry the weight); the other controllers do not
// settle that way (measured: a policy sank at 8 cm/s, a rover dropped faster after settling
// than before), so their robots start as placed.
struct SettleJoints {
  std::vector<int> owner;  // per joint: the free joint it moves with, -1 = none (kept)
  std::vector<int> bases;  // the robots' free joints
};

SettleJoints FloatingRobotJoints(const WorldConfig& world, const ModelInfo& info) {
  const int nbody = static_cast<int>(info.body_names.size());
  std::vector<char> robot_body(nbody, 0);
  for (const ModelConfig& m : world.models) {
    if (!m.is_robot || m.controller.type != "trot_gait") continue;
    for (int b = 0; b < nbody; ++b)
      if (info.body_names[b].rfind(m.name + "/", 0) == 0) robot_body[b] = 1;
  }
  // the free joint each body moves with (its own or its nearest ancestor's), -1 = none
  std::vector<int> free_of_body(nbody, -1);
  SettleJoints out;
  for (size_t j = 0; j < info.joints.size(); ++j)
    if (info.joints[j].type == JointInfo::Type::kFree && robot_body[info.joints[j].body]) {
      free_of_body[info.joints[j].body] = static_cast<int>(j);
      out.bases.push_back(static_cast<int>(j));
    }
  for (int b = 1; b < nbody; ++b) {
    const int p = info.body_parent[b];
    if (free_of_body[b] < 0 && p > 0) free_of_body[b] = free_of_body[p];
  }
  out.owner.assign(info.joints.size(), -1);
  for (size_t j = 0; j < info.joints.size(); ++j) out.owner[j] = free_of_body[info.joints[j].body];
  return out;
}

// the rotation about world z of unit quaternion q (w, x, y, z): its twist about z
Eigen::Quaterniond TwistAboutZ(const Eigen::Quaterniond& q) {
  Eigen::Quaterniond t(q.w(), 0, 0, q.z());
  if (t.norm() < 1e-12) return Eigen::Quaterniond::Identity();
  return t.normalized();
}

// the fields a settle changes: the physics state proper (positions, velocities, activations
// and the constraint solver's warm start); controls, applied forces, mocap poses and the
// controllers' schedule stay the start's
void CopySettledFields(const SimState& from, SimState* to) {
  for (const StateFieldInfo& f : kStateFields) {
    const bool settled = f.field == StateField::kQpos || f.field == StateField::kQvel ||
                         f.field == StateField::kAct || f.field == StateField::kQaccWarmstart;
    if (settled) to->*f.f64 = from.*f.f64;
  }
}

// how long robots settle before t = 0 (SettledState), s
constexpr double kSettleSec = 0.2;
// how far a settling base may sink before it counts as in the air (it then keeps its start), m:
// robots sink into their soft contacts by millimetres, 0.2 s of free fall drops 0.196 m
constexpr double kMaxSettleDropM = 0.05;
// how far a settling base may rise (a controller's thrust or push at t = 0 stops there), m
constexpr double kMaxSettleRiseM = 0.01;

// the state robots with a floating base (a free joint) driven by trot_gait (FloatingRobotJoints)
// start a run in, at rest on their
// contacts: a soft contact carries a robot only once pressed in, and a controller's first
// command is for the pose it finds, so a robot placed touching the ground in its standing pose
// would first drop and bounce (an IMU on it read 3.6 m/s^2 at t = 0, not gravity). the composed
// model (assets relative to `asset_dir`; the world's initial keyframes applied) is stepped for
// kSettleSec on a scratch Simulation with the world's controllers, each reset before every
// step so that it acts as at t = 0 on the state reached (a gait holds its stance, a waypoint
// follower gives its first command); each floating base may sink or rise by up to
// kMaxSettleRiseM and tilt but keeps its x, y and heading; every other joint keeps its start,
// and so does a base that drops more than kMaxSettleDropM (a body dropped from a height).
// returns that state (velocities as settled: near zero, e.g. the quadruped's base rises at
// 9 mm/s as its gait holds it) at step 0 and time 0, with the start's ctrl,
// applied forces and mocap poses; without a floating robot, the start state. deterministic
// and the same with or without the caller's controllers: a replay starts where the run did.
// `terrain` gives the ray caster a controller with a height scan needs.
SimState SettledState(const WorldConfig& world, const std::string& composed_xml,
                      const std::string& asset_dir,
                      const std::function<TerrainRayCaster*()>& terrain) {
  Simulation sim = Simulation::LoadFromString(composed_xml, world.timestep_sec, asset_dir);
  sim.TakeWarnings();
  for (const ModelConfig& m : world.models) {
    if (m.initial_keyframe.empty()) continue;
    sim.ApplyKeyframe(m.name + "/" + m.initial_keyframe, m.name + "/",
                      (m.key.empty() ? "models[" + m.name + "]" : m.key) + ".initial_keyframe");
  }
  const SimState s0 = sim.GetState();
  const SettleJoints joints = FloatingRobotJoints(world, sim.model_info());
  if (joints.bases.empty()) return s0;
  AddWorldControllers(world, &sim);
  for (int i = 0; i < sim.num_controllers(); ++i) {
    TerrainRayCasterUser* user = AsTerrainRayCasterUser(sim.mutable_controller(i));
    if (user && user->needs_terrain_ray_caster()) user->SetTerrainRayCaster(terrain());
  }
  const std::vector<JointInfo>& info = sim.model_info().joints;
  const int steps = static_cast<int>(std::ceil(kSettleSec / sim.timestep() - 1e-9));
  // a base that drops further than a robot sinks into its contacts is in the air: it keeps its
  // start (a drone hovering, a body dropped from a height)
  std::vector<char> airborne(info.size(), 0);
  SimState s;
  for (int k = 0; k < steps; ++k) {
    // every controller as at t = 0, on the state reached
    sim.ResetControllers();
    sim.Step();
    sim.GetState(&s);
    for (const int f : joints.bases)
      if (s0.qpos[info[f].qpos_adr + 2] - s.qpos[info[f].qpos_adr + 2] > kMaxSettleDropM)
        airborne[f] = 1;
    for (size_t j = 0; j < info.size(); ++j) {
      const JointInfo& J = info[j];
      const int nq = J.type == JointInfo::Type::kFree   ? 7
                     : J.type == JointInfo::Type::kBall ? 4
                                                        : 1;
      const int nv = J.type == JointInfo::Type::kFree   ? 6
                     : J.type == JointInfo::Type::kBall ? 3
                                                        : 1;
      const int f = joints.owner[j];
      if (f < 0 || airborne[f]) {
        // other models' joints and bodies in the air keep their start
        for (int i = 0; i < nq; ++i) s.qpos[J.qpos_adr + i] = s0.qpos[J.qpos_adr + i];
        for (int i = 0; i < nv; ++i) s.qvel[J.dof_adr + i] = 0;
        continue;
      }
      if (f != static_cast<int>(j)) continue;
      // a floating base sinks into its contacts or rises from them and tilts, but does not
      // travel or turn
      double* q = s.qpos.data() + J.qpos_adr;
      const double* q0 = s0.qpos.data() + J.qpos_adr;
      q[0] = q0[0], q[1] = q0[1], q[2] = std::min(q[2], q0[2] + kMaxSettleRiseM);
      const Eigen::Quaterniond r(q[3], q[4], q[5], q[6]), r0(q0[3], q0[4], q0[5], q0[6]);
      const Eigen::Quaterniond fixed =
          (TwistAboutZ(r0.normalized()) * TwistAboutZ(r.normalized()).inverse() * r.normalized())
              .normalized();
      q[3] = fixed.w(), q[4] = fixed.x(), q[5] = fixed.y(), q[6] = fixed.z();
      double* v = s.qvel.data() + J.dof_adr;
      v[0] = v[1] = 0;
      if (q[2] >= q0[2] + kMaxSettleRiseM) v[2] = std::min(v[2], 0.0);
      // angular velocity (body frame) without its part about world z
      const Eigen::Matrix3d R = fixed.toRotationMatrix();
      Eigen::Vector3d w_W = R * Eigen::Vector3d(v[3], v[4], v[5]);
      w_W.z() = 0;
      const Eigen::Vector3d w_B = R.transpose() * w_W;
      v[3] = w_B.x(), v[4] = w_B.y(), v[5] = w_B.z();
    }
    // agents stay where they start
    s.mocap_pos = s0.mocap_pos;
    s.mocap_quat = s0.mocap_quat;
    sim.SetState(s);
  }
  // at time 0: the settled positions and velocities (near zero; not zeroed: a base held by its
  // controller keeps the slow motion it settled into, and zeroing it would drop the damping
  // that balances it), the start's controls, applied forces and mocap poses
  SimState out = s0;
  CopySettledFields(s, &out);
  out.controller_next_update.clear();
  return out;
}

}  // namespace

SetupInterrupted::SetupInterrupted(int signal, const std::string& step)
    : Error(std::string("interrupted by ") + SignalName(signal) + " while " + step +
            ", before the run started"),
      signal_(signal) {}

void AddWorldControllers(const WorldConfig& world, Simulation* sim) {
  for (const ModelConfig& m : world.models) {
    if (!m.is_robot || m.controller.type.empty()) continue;
    sim->AddController(MakeController(m.controller, m.name, world.file));
  }
}

Session::Session(const WorldConfig& world, const SessionOptions& options) : world_(world) {
  world_.render.seed = world_.seed;
  // a stop request ends the set-up between its steps (SetupInterrupted)
  const auto poll = [&options](const char* step) {
    if (!options.stop_request) return;
    if (const int sig = options.stop_request->load()) throw SetupInterrupted(sig, step);
  };
  poll("starting");

  // compose every model into one MJCF, with the world's IMUs and the agents' bodies
  auto t0 = Clock::now();
  ComposeOptions compose_options;
  // URDF meshes MuJoCo cannot read become STL files next to the composed model (a "meshes"
  // folder beside composed.xml), or in the temporary folder when none is written
  std::string mesh_dir;
  if (!options.composed_xml_path.empty())
    mesh_dir = (std::filesystem::path(options.composed_xml_path).parent_path() / "meshes").string();
  compose_options.prepare_urdf = [mesh_dir](const std::string& urdf_path) {
    return PrepareUrdfForMujoco(urdf_path, mesh_dir);
  };
  compose_options.timestep_sec = world_.timestep_sec;
  compose_options.physics = world_.physics;
  compose_options.ground_plane = world_.ground_plane;
  // generated environments (models: entries with environment:) become MJCF models next to the
  // composed model ("environments"), mesh files MJCF models in mesh_dir (environment/
  // model_sources.h: their lamps become world lights, their materials come in the scene step)
  const ModelSources sources(
      &world_,
      options.composed_xml_path.empty()
          ? std::string()
          : (std::filesystem::path(options.composed_xml_path).parent_path() / "environments")
                .string(),
      mesh_dir);
  compose_options.convert_mesh = [&sources](const std::string& file) {
    return sources.ConvertMjcfMesh(file);
  };
  ComposedScene composed = ComposeWorld(sources.models(), compose_options);
  poll("composing the models");
  AddImuSensors(world_.sensors, &composed);  // world-file IMUs (compose/imu_injection.h)
  effects_ =
      std::make_unique<EffectsStage>(world_, &composed, options.adversity,
                                     options.reserve_live_npcs, sources.crowd_sites(world_.models));
  poll("planning the effects and agents");
  for (const std::string& w : composed.warnings) spdlog::warn("composer: {}", w);
  // the document becomes text once: the file kept and what MuJoCo compiles
  composed_xml_ = composed.Xml();
  const std::string& xml = composed_xml_;
  if (!options.composed_xml_path.empty()) WriteFileAtomic(options.composed_xml_path, xml);
  timings_.compose_sec = SecondsSince(t0);

  // physics (compiled once; a second, earlier compile only for an adversity preset's
  // planning, session/effects_stage.h), agent drivers and controllers
  t0 = Clock::now();
  // every model compiled when it was composed (session/world_composer.h): an error now is in
  // Penumbra's additions (IMU sites, agents), named by its line in the composed text
  sim_ = std::make_unique<Simulation>(
      options.composed_xml_path.empty()
          ? Simulation::LoadFromString(xml, world_.timestep_sec)
          : Simulation::LoadFromFile(options.composed_xml_path, world_.timestep_sec));
  // the world file's initial_keyframe of each model, before anything reads the state
  for (const ModelConfig& m : world_.models) {
    if (m.initial_keyframe.empty()) continue;
    sim_->ApplyKeyframe(m.name + "/" + m.initial_keyframe, m.name + "/",
                        (m.key.empty() ? "models[" + m.name + "]" : m.key) + ".initial_keyframe");
  }
  poll("compiling the model");
  effects_->Attach(sim_.get());  // checks the world's agents against the model
  if (options.add_controllers) AddWorldControllers(world_, sim_.get());
  timings_.load_sec = SecondsSince(t0);

  // the renderer's static scene, the effects engine on it, and the renderer
  t0 = Clock::now();
  SceneDescription extracted = sim_->scene();
  sources.ApplyMaterials(world_.file, &extracted);
  poll("loading the model");
  scene_ = effects_->Bind(AssembleScene(std::move(extracted), world_, sim_->Snapshot()));
  poll("assembling the scene");
  if (options.check_run_budget) {
    CheckRunMemory(world_, scene_, PhysicalMemoryBytes());  // before allocating
    if (auto work = DescribeRunWork(EstimateRunWork(world_, scene_, sim_->timestep())))
      spdlog::warn("{}", *work);
  }
  if (options.build_renderer) {
    renderer_ = MakeRenderer(scene_, world_.render);
    poll("building the renderer");
  }
  // controllers with a height scan (policies) cast rays onto the static scene (the terrain)
  for (int i = 0; i < sim_->num_controllers(); ++i) {
    TerrainRayCasterUser* user = AsTerrainRayCasterUser(sim_->mutable_controller(i));
    if (!user || !user->needs_terrain_ray_caster()) continue;
    if (!terrain_)
      terrain_ =
          std::make_unique<StaticTerrainRayCaster>(scene_, sim_->Snapshot(), world_.render.backend);
    user->SetTerrainRayCaster(terrain_.get());
  }
  timings_.scene_build_sec = SecondsSince(t0);

  // robots with a floating base start at rest on their contacts (SettledState); the same with
  // or without the session's controllers, so a replay starts where the run did
  const std::string asset_dir =
      options.composed_xml_path.empty()
          ? std::string()
          : std::filesystem::path(options.composed_xml_path).parent_path().string();
  if (!FloatingRobotJoints(world_, sim_->model_info()).bases.empty()) {
    const SimState settled = SettledState(world_, xml, asset_dir, [this]() -> TerrainRayCaster* {
      if (!terrain_)
        terrain_ = std::make_unique<StaticTerrainRayCaster>(scene_, sim_->Snapshot(),
                                                            world_.render.backend);
      return terrain_.get();
    });
    SimState now = sim_->GetState();
    CopySettledFields(settled, &now);
    sim_->SetState(now);
    poll("settling the robots");
  }
}

Session::~Session() = default;

}  // namespace penumbra
