#include "penumbra/session/session.h"

#include <spdlog/spdlog.h>

#include <chrono>
#include <csignal>
#include <filesystem>

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
  compose_options.urdf_to_mjcf = [mesh_dir](const std::string& urdf_path) {
    return ConvertUrdfToMjcfInto(urdf_path, mesh_dir);
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
  ComposedScene composed = ComposeWorld(sources.models(), compose_options);
  poll("composing the models");
  sources.ConvertComposedMeshes(&composed);
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
  try {
    sim_ = std::make_unique<Simulation>(
        options.composed_xml_path.empty()
            ? Simulation::LoadFromString(xml, world_.timestep_sec)
            : Simulation::LoadFromFile(options.composed_xml_path, world_.timestep_sec));
  } catch (const ConfigError& e) {
    // MuJoCo names a line of the composed text: name the model file and line instead
    // MuJoCo 2.2.2's collision detection takes nbody (nbody - 1) / 2 doubles of its stack
    // (scene/scene_limits.h kMaxAgents): say so instead of only "Stack overflow"
    if (e.problem().find("Stack overflow") != std::string::npos) {
      size_t bodies = 1;  // the world body
      for (size_t at = xml.find("<body"); at != std::string::npos; at = xml.find("<body", at + 5))
        ++bodies;
      throw ConfigError(
          e.file(), e.line(), e.key(),
          e.problem() + " (the composed model has " + std::to_string(bodies) +
              " bodies, agents' included; MuJoCo 2.2.2's collision detection needs nbody (nbody - "
              "1) / 2 doubles of its stack every step, and its automatic stack holds that up to "
              "about 1,650 bodies; expected fewer bodies or agents, or a <size nstack=\"...\"/> in "
              "a model)");
    }
    throw LocateComposedError(composed, e);
  }
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
}

Session::~Session() = default;

}  // namespace penumbra
