#pragma once
// a world loaded once: the one set-up sequence shared by `penumbra run`, the benchmarks, the
// contact sheet and the tests. in order (each step's errors stop it; nothing is retried):
//   1. compose   every model into one MJCF document (session/world_composer.h), the world's
//                IMUs added to it (compose/imu_injection.h), then the effects stage plans the
//                world's effects, agents and adversity preset and adds one mocap body per agent
//                (session/effects_stage.h), all on one tinyxml2 document, printed to text
//                once and written to SessionOptions::composed_xml_path when one is given;
//   2. load      MuJoCo compiles the text into the Simulation (the only compile, except for
//                a world with an adversity preset, whose planner compiled a probe of the
//                document without its NPCs in step 1); the world's agents are checked
//                against the model and their mocap drivers added, then the robots'
//                controllers (control/controller_factory.h);
//   3. scene     the renderer's SceneDescription: the compiled model's scene joined with the
//                world file's lights, sky, cameras and materials (session/scene_assembly.h),
//                agent geoms labelled and the effects engine built on it (EffectsStage::Bind);
//                optionally the run's memory and work are checked (world/run_budget.h);
//                then the renderer (render/renderer.h) is built for that scene, and policy
//                controllers with a height scan get the static scene's terrain ray caster
//                (session/static_terrain_ray_caster.h).
// a Session is then stepped and rendered by its user (run/runner.cc, bench/bench.cc, ...); it
// owns everything it built and is neither copied nor moved (what it hands out by reference
// stays valid for its lifetime).

#include <atomic>
#include <memory>
#include <string>
#include <vector>

#include "penumbra/control/terrain_ray_caster.h"
#include "penumbra/core/error.h"
#include "penumbra/physics/simulation.h"
#include "penumbra/render/renderer.h"
#include "penumbra/scene/scene_description.h"
#include "penumbra/session/effects_stage.h"
#include "penumbra/world/world_config.h"

namespace penumbra {

/// how a Session is set up; the defaults load a world to be stepped and rendered.
struct SessionOptions {
  /// an adversity preset spec from the command line (--adversity, world/adversity_preset.h), or
  /// "" for the world's own `adversity` key.
  std::string adversity;
  /// where to keep the composed MJCF (e.g. "<output_dir>/composed.xml"); MuJoCo then loads
  /// that file, so its messages (and PhysicsError's) name it. "" = loaded from memory
  /// (messages name "<string>"), nothing written. URDF meshes MuJoCo cannot read
  /// (DAE, ...) are converted to STL files in "meshes/" beside it ("" = in the temporary
  /// folder's "penumbra-urdf-meshes"; physics/urdf_converter.h).
  std::string composed_xml_path;
  /// add the controllers of the world's robots (AddWorldControllers).
  bool add_controllers = true;
  /// a live run (bridges, viewer): reserve parked bodies for the NPCs of the bundled adversity
  /// presets (session/effects_stage.h LiveNpcReserve), so that `set_adversity` to one of them
  /// works at run time. changes the composed model (more mocap bodies): a replay of such a
  /// run sets it too (replay/recorded_world.h RecordedRunFlags::live).
  bool reserve_live_npcs = false;
  /// before the renderer is built: refuse a run whose cameras and LiDARs would not fit in the
  /// machine's physical memory (CheckRunMemory) and warn about a large amount of work
  /// (DescribeRunWork), as `penumbra run` does.
  bool check_run_budget = false;
  /// build the renderer (render/backends/: MakeRenderer with the world's render
  /// settings); off for physics- or sensor-only work and for callers with their own render
  /// settings.
  bool build_renderer = true;
  /// a stop request (0, or the number of the signal that asked to stop; app/stop_signals.h),
  /// polled between the set-up steps (compose, compile, scene, renderer): once it is set,
  /// the constructor throws SetupInterrupted instead of finishing the set-up. null = never.
  const std::atomic<int>* stop_request = nullptr;
};

/// what a Session's constructor throws when its SessionOptions::stop_request was set while it
/// set the world up (a SIGTERM during a long composition): nothing is left half-built.
class SetupInterrupted : public Error {
 public:
  /// `signal` is the stop request's value (SIGINT, SIGTERM); `step` names the set-up step it
  /// ended ("composing the models").
  SetupInterrupted(int signal, const std::string& step);
  int signal() const { return signal_; }

 private:
  int signal_ = 0;
};

/// wall-clock seconds of the set-up steps (run.json timings_sec: compose_sec, load_sec,
/// scene_build_sec).
struct SessionTimings {
  double compose_sec = 0;      ///< compose, IMUs, effects planning and agents, composed.xml
  double load_sec = 0;         ///< MuJoCo compile, controllers, mocap drivers
  double scene_build_sec = 0;  ///< scene assembly, effects engine, run budget, renderer
};

/// adds a controller (control/controller_factory.h: MakeController) for every robot of
/// `world` that has one, in world order.
/// @throws ConfigError from the factory or Controller::Initialize (unknown type, bad
///         parameter, a name missing from the model), naming the world file.
void AddWorldControllers(const WorldConfig& world, Simulation* sim);

/// a world composed, compiled and made ready to step and render, once.
class Session {
 public:
  /// sets `world` up as the file header describes. world.render.seed is set to world.seed.
  /// @throws ConfigError for bad input found on the way (composer, IMUs, effects, agents,
  ///         preset, MuJoCo, controllers, scene assembly, effects engine, run budget; each
  ///         names its file, line and key as the stage that finds it does); Error when
  ///         composed_xml_path cannot be written; PhysicsError if MuJoCo fails to set up.
  explicit Session(const WorldConfig& world, const SessionOptions& options = {});
  ~Session();
  Session(const Session&) = delete;
  Session& operator=(const Session&) = delete;

  /// the world as set up (render.seed = seed).
  const WorldConfig& world() const { return world_; }
  /// the simulation, with its controllers and agent drivers, at time 0 until stepped.
  Simulation& sim() { return *sim_; }
  const Simulation& sim() const { return *sim_; }
  /// the renderer's static scene (cameras with their final sizes).
  const SceneDescription& scene() const { return scene_; }
  /// the renderer for scene(); null when SessionOptions::build_renderer is off.
  Renderer* renderer() const { return renderer_.get(); }
  /// the run's effects, agents and preset; Evaluate gives the effects per viewer.
  EffectsStage& effects() { return *effects_; }
  const EffectsStage& effects() const { return *effects_; }
  /// the composed MJCF text MuJoCo compiled (what composed.xml holds).
  const std::string& composed_xml() const { return composed_xml_; }
  /// seconds each set-up step took.
  const SessionTimings& timings() const { return timings_; }

 private:
  WorldConfig world_;
  std::unique_ptr<EffectsStage> effects_;
  /// the height scans' ray caster (null without one); outlives sim_'s controllers that use it
  std::unique_ptr<TerrainRayCaster> terrain_;
  std::unique_ptr<Simulation> sim_;
  SceneDescription scene_;
  std::unique_ptr<Renderer> renderer_;
  SessionTimings timings_;
  std::string composed_xml_;
};

}  // namespace penumbra
