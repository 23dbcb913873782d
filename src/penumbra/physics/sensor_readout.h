#pragma once
// metadata of a model's MuJoCo-native sensors (<sensor> elements of the MJCF): name, type,
// dimension, unit and the object each one is attached to, so that every sensor can be
// read by name from WorldSnapshot::sensordata (Simulation::Snapshot fills it for the
// snapshot's own instant).
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

#include <string>
#include <vector>

struct mjModel_;

namespace penumbra {

/// one MuJoCo sensor.
struct MujocoSensorInfo {
  std::string name;  ///< MJCF name (composed: "<model>/<name>"); "" if unnamed
  int id = -1;       ///< MuJoCo sensor id
  std::string type;  ///< MJCF element name: "touch", "accelerometer", "framequat", ...
  int adr = 0;       ///< first index in sensordata
  int dim = 0;       ///< number of values
  std::string unit;  ///< e.g. "N", "m/s^2", "rad", "1" (dimensionless)
  /// per-value labels: "" (dim 1), "x" "y" "z" (vectors) or "w" "x" "y" "z" (quaternions)
  std::vector<std::string> components;
  std::string object_type;     ///< "site", "body", "joint", "tendon", "actuator", "geom", ...
  std::string object_name;     ///< name of the attached object ("" if none / unnamed)
  std::string reference_name;  ///< frame sensors' reference object ("" = world)
  double noise_stddev = 0;     ///< the MJCF noise attribute (MuJoCo itself does not add it)
  double cutoff = 0;           ///< MJCF cutoff (0 = none)
};

/// every sensor of the model, by id.
std::vector<MujocoSensorInfo> DescribeMujocoSensors(const mjModel_* m);

/// index of the sensor named `name` in `sensors`, or -1.
int FindMujocoSensor(const std::vector<MujocoSensorInfo>& sensors, const std::string& name);

/// the column label of value k of a sensor: "<name>" for scalars, "<name>_x" etc. for vectors.
std::string SensorValueLabel(const MujocoSensorInfo& s, int k);

}  // namespace penumbra
