#pragma once
// what a live run is made of, as the `model_info` reply describes it (docs/zmq-protocol.md,
// "model_info"): the model's names and index maps, the cameras with their intrinsics, the
// world file's sensors and the controllers with the commands each accepts.

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "penumbra/session/session.h"
#include "penumbra/world/world_config.h"

namespace penumbra {

// the command names a controller accepts: ControllerCommands (control/controller_capabilities.h).

/// the robot a controller belongs to, from its context key "robots[NAME].controller"
/// ("" for a controller built in code).
std::string ControllerRobot(const Controller& controller);

/// the `model_info` reply fields for `session` (set up from `world`, the world with the run's
/// overrides): timestep_sec, nq, nv, nu, nmocap, nsensordata, seed, end_time_sec, bodies,
/// joints, actuators, mujoco_sensors, mocap_bodies, keyframes, cameras (name, width, height,
/// fx, fy, cx, cy, distortion k1 k2 p1 p2 k3, rate_hz, frame_id "<camera>/optical",
/// outputs), sensors (name, type, rate_hz, frame_id) and controllers (index, robot, type,
/// commands).
nlohmann::json DescribeRun(Session& session, const WorldConfig& world);

}  // namespace penumbra
