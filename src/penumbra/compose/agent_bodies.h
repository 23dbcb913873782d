#pragma once
// MJCF bodies for NPC agents: per MocapBodySpec (compose/mocap_body_spec.h; the
// effects module's agents are converted to specs by session/effects_stage.cc) one mocap root
// body and one mocap body per moving part (a person's limb segments, a vehicle's wheels;
// effects/agent_animation.h), added to a composed scene after ComposeWorld. the bodies are
// kinematic (MuJoCo mocap: no joints, posed through mocap_pos / mocap_quat by physics
// Simulation::AddMocapDriver; session/agent_drivers.h drives the root from the agent's path and
// each part from the root and its joint angles), so robots and free bodies collide with them
// and are pushed, while agents never react to contact. MuJoCo allows mocap bodies only as
// children of the world, so the articulation is computed (effects/walker_gait.h forward
// kinematics), not a MuJoCo joint tree: hinge joints would make the limbs dynamic (pushed by
// the robot, changing nq / nv). MuJoCo filters contacts between bodies welded to the world, so
// agents pass through static furniture and each other and only touch moving bodies.
//
// names: root body "agents/<name>" (AgentBodyName), part bodies "agents/<name>/<part>"
// (AgentPartBodyName; parts: effects/agent_animation.h AgentPartNames), geoms
// "agents/<name>/<geom>". geoms have contype = conaffinity = 1 (MuJoCo's default), so they
// collide with every geom whose contype or conaffinity has bit 0 set (all bundled robots);
// condim 3, friction 0.8.
//
// shapes (frames: effects/walker_gait.h for a person, body frame B = agent frame A for a
// vehicle root: origin on the floor, x forward, y left, z up; H = height_m):
//   person    root: pelvis box, torso box (0.126 H x 0.218 H x 0.24 H), neck capsule, head
//             sphere r 0.063 H (top at H); thighs (capsule r 0.04 H), shins (r 0.03 H) with a
//             foot box 0.15 H long, upper arms (r 0.026 H), forearms (r 0.022 H) with a hand
//             sphere; segment lengths of effects/walker_gait.h. colours from the spec (shirt:
//             torso, upper arms; trousers: pelvis, legs; skin: head, neck, forearms, hands).
//   forklift  about 2.75 x 1.1 x 2.1 m overall: chassis 1.6 x 1.1 x 0.7 m, counterweight,
//             mast (two 2.0 m uprights), overhead guard at 2.1 m on four posts, two forks
//             1.1 m long in front (x = 0.8 ... 1.9 m) 0.1 m above the floor; four wheel
//             bodies (cylinders r 0.25 m, a steel hub bar that shows the spin).
//   cart      deck 1.0 x 0.6 m at 0.3 m, push handle 1.0 m high; four wheel bodies (r 0.1 m).

#include <string>
#include <vector>

#include "penumbra/compose/mocap_body_spec.h"
#include "penumbra/compose/scene_composer.h"
#include "penumbra/effects/agent_path.h"

namespace penumbra {

/// MJCF body name of agent `agent_name` ("agents/<name>").
std::string AgentBodyName(const std::string& agent_name);

/// MJCF body name of the part `part` of agent `agent_name` ("agents/<name>/<part>").
std::string AgentPartBodyName(const std::string& agent_name, const std::string& part);

/// true when `body_name` is the root or a part body of agent `agent_name`.
bool IsAgentBodyOf(const std::string& body_name, const std::string& agent_name);

/// the agent kind whose bodies a shape gets (effects/agent_animation.h).
AgentKind AgentKindOfShape(MocapBodySpec::Shape shape);

/// adds per spec its root and part mocap bodies (standing still at its X_WB: the parts at the
/// standing pose of effects/agent_animation.h) to scene->document (in place), and extends
/// every keyframe's mpos / mquat by the bodies' initial poses (root, then parts, per spec).
/// @throws Error if a spec is invalid (ValidateMocapBodySpecsOrThrow); ConfigError(world_file,
///         0, "models") if a model is named "agents" (its names would clash), or
///         ConfigError(world_file, 0, "agents") if the composed document has no <mujoco> root.
void AddAgentBodies(const std::vector<MocapBodySpec>& bodies, const std::string& world_file,
                    ComposedScene* scene);

}  // namespace penumbra
