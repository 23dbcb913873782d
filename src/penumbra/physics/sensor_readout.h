#pragma once
// metadata of a model's MuJoCo-native sensors (<sensor> elements of the MJCF) as the
// engine-neutral SensorDescription of scene/sensor_description.h: name, type, dimension, unit and
// the object each one is attached to, so that every sensor can be read by name from
// WorldSnapshot::sensordata (Simulation::Snapshot fills it for the snapshot's own instant).
//
// every sensor type of MuJoCo 4.0 (mjtSensor) is named by its MJCF element. units follow the
// MuJoCo 4.0 XML reference ("sensor" section): touch N (normal force summed over the site's
// zone), force N and torque N m (between the site's body and its parent, in the site frame),
// accelerometer m/s^2 (specific force: reads +g up at rest, 0 in free fall), velocimeter m/s,
// gyro rad/s, magnetometer in the units of <option magnetic>, rangefinder m (-1 = nothing
// within range along the site's +z), camprojection px (u right, v down from the image's
// top-left corner, the camera's resolution), jointpos / jointlimitpos rad (hinge) or m (slide),
// jointvel rad/s or m/s, jointactuatorfrc N m or N, tendonactuatorfrc N, ballquat and
// framequat unit quaternion (w, x, y, z), framepos / subtreecom m, frame axes unit vectors,
// framelinvel m/s, frameangvel rad/s, framelinacc m/s^2, frameangacc rad/s^2,
// subtreelinvel m/s, subtreeangmom kg m^2/s, tendonpos m, tendonvel m/s, actuator
// position / velocity / force in the transmission's units (rad or m, N or N m), insidesite 1
// (1 inside, 0 outside), distance m (signed, capped at the sensor's cutoff), normal unit
// vector, fromto m (from_x..z, to_x..z), e_potential / e_kinetic J, clock s.
//
// sensors whose values have several units have unit "" and carry the unit in each component
// label: contact "<slot>_<field>[_x|_y|_z][_<unit>]" for the fields of its data attribute
// (found, force N, torque N m, dist m, pos m, normal, tangent, linvel m/s, angvel rad/s; found
// = number of matching contacts, 0 = empty slot), rangefinder with a data attribute other than
// dist ("[<ray>_]<field>[_x|_y|_z][_<unit>]", one ray per camera pixel on a camera), tactile
// "depth_<i>_m", "slip1_<i>_m_s", "slip2_<i>_m_s" per taxel i (mesh vertex). user and plugin
// sensors (values written by a callback or a plugin) have unit "".

#include <vector>

#include "penumbra/scene/sensor_description.h"

struct mjModel_;

namespace penumbra {

/// every sensor of the model, by id, as engine-neutral SensorDescription (units as listed above).
/// delayed and interval sensors (nsample, delay, interval) read what MuJoCo reads: their history
/// buffers are part of the state a snapshot copies (scene/sim_state.h).
/// @throws Error naming the sensor for a sensor type Penumbra does not know or values that do
/// not match the layout the sensor's attributes give.
std::vector<SensorDescription> DescribeMujocoSensors(const mjModel_* m);

}  // namespace penumbra
