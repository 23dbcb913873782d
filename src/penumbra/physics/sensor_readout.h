#pragma once
// metadata of a model's MuJoCo-native sensors (<sensor> elements of the MJCF) as the
// engine-neutral SensorDescription of scene/sensor_description.h: name, type, dimension, unit and
// the object each one is attached to, so that every sensor can be read by name from
// WorldSnapshot::sensordata (Simulation::Snapshot fills it for the snapshot's own instant).
//
// units follow the MuJoCo 2.2.2 XML reference ("sensor" section): touch N (normal force
// summed over the site's zone), force N and torque N m (between the site's body and its
// parent, in the site frame), accelerometer m/s^2 (specific force: reads +g up at rest,
// 0 in free fall), velocimeter m/s, gyro rad/s, magnetometer in the units of
// <option magnetic>, rangefinder m (-1 = nothing within range along the site's +z),
// jointpos / jointlimitpos rad (hinge) or m (slide), jointvel rad/s or m/s, ballquat and
// framequat unit quaternion (w, x, y, z), framepos / subtreecom m, frame axes unit vectors,
// framelinvel m/s, frameangvel rad/s, framelinacc m/s^2, frameangacc rad/s^2,
// subtreelinvel m/s, subtreeangmom kg m^2/s, tendonpos m, tendonvel m/s, actuator
// position / velocity / force in the transmission's units (rad or m, N or N m), clock s.

#include <vector>

#include "penumbra/scene/sensor_description.h"

struct mjModel_;

namespace penumbra {

/// every sensor of the model, by id, as engine-neutral SensorDescription (units as listed above).
std::vector<SensorDescription> DescribeMujocoSensors(const mjModel_* m);

}  // namespace penumbra
