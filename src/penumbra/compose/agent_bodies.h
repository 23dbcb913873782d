#pragma once
// MJCF bodies for NPC agents: one mocap body per MocapBodySpec (compose/mocap_body_spec.h; the
// effects module's agents are converted to specs by app/effects_stage.cc), added to a composed
// scene after ComposeWorld. the bodies are kinematic (MuJoCo mocap: no joints,
// posed through mocap_pos / mocap_quat by physics Simulation::AddMocapDriver), so robots
// and free bodies collide with them and are pushed, while agents never react to contact.
// MuJoCo filters contacts between bodies welded to the world, so agents pass through
// static furniture and each other and only touch moving bodies.
//
// names: body "agents/<name>", geoms "agents/<name>/<part>" (AgentBodyName). geoms have
// contype = conaffinity = 1 (MuJoCo's default), so they collide with every geom whose
// contype or conaffinity has bit 0 set (all bundled robots); condim 3, friction 0.8.
//
// shapes (body frame B: origin on the floor, x forward, y left, z up; MocapBodySpec::Shape):
//   person    legs and arms capsules (r 0.07 / 0.05 m), torso box 0.22 x 0.38 x 0.5 m,
//             pelvis box, head sphere r 0.11 m; all heights scale with height_m / 1.75.
//   forklift  about 2.75 x 1.1 x 2.1 m overall: chassis 1.6 x 1.1 x 0.7 m, counterweight, four
//   wheels (cylinders r 0.25 m),
//             mast (two 2.0 m uprights), overhead guard at 2.1 m on four posts, two forks
//             1.1 m long in front (x = 0.8 ... 1.9 m) 0.1 m above the floor.
//   cart      deck 1.0 x 0.6 m at 0.3 m, four wheels (r 0.1 m), push handle 1.0 m high.

#include <string>
#include <vector>

#include "penumbra/compose/mocap_body_spec.h"
#include "penumbra/compose/scene_composer.h"

namespace penumbra {

/// MJCF body name of agent `agent_name` ("agents/<name>").
std::string AgentBodyName(const std::string& agent_name);

/// adds one mocap body per spec (placed at its X_WB) to scene->document (in place), and extends
/// every keyframe's mpos / mquat by the bodies' initial poses. a person's shirt colour is picked
/// from a fixed palette by the spec's index in `bodies`.
/// @throws Error if a spec is invalid (ValidateMocapBodySpecsOrThrow); ConfigError(world_file,
///         0, "models") if a model is named "agents" (its names would clash), or
///         ConfigError(world_file, 0, "agents") if the composed document has no <mujoco> root.
void AddAgentBodies(const std::vector<MocapBodySpec>& bodies, const std::string& world_file,
                    ComposedScene* scene);

}  // namespace penumbra
