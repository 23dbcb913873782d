#pragma once
// what a world's engine-native sensors are: name, type, where their values sit in
// WorldSnapshot::sensordata, dimension, unit and the object each one is attached to. the
// physics engine fills it (physics/sensor_readout.h: DescribeMujocoSensors, whose header lists
// every type's unit; Simulation::sensor_info()); sensors/ reads values by it without knowing
// the engine.

#include <string>
#include <vector>

namespace penumbra {

/// one engine-native sensor (an MJCF <sensor> element for MuJoCo).
struct SensorDescription {
  std::string name;  ///< model name (composed: "<model>/<name>"); "" if unnamed
  int id = -1;       ///< the engine's sensor id (MuJoCo sensor id)
  std::string type;  ///< MJCF element name: "touch", "accelerometer", "framequat", ...
  int adr = 0;       ///< first index in WorldSnapshot::sensordata
  int dim = 0;       ///< number of values
  std::string unit;  ///< e.g. "N", "m/s^2", "rad", "1" (dimensionless)
  /// per-value labels: "" (dim 1), "x" "y" "z" (vectors), "w" "x" "y" "z" (quaternions), else
  /// "0" "1" ...
  std::vector<std::string> components;
  std::string object_type;     ///< "site", "body", "joint", "tendon", "actuator", "geom", ...
  std::string object_name;     ///< name of the attached object ("" if none / unnamed)
  std::string reference_name;  ///< frame sensors' reference object ("" = world)
  double noise_stddev = 0;     ///< the model's noise attribute (MuJoCo itself does not add it)
  double cutoff = 0;           ///< the model's cutoff (0 = none)
};

/// index of the sensor named `name` in `sensors`, or -1.
int FindSensor(const std::vector<SensorDescription>& sensors, const std::string& name);

/// the column label of value k of a sensor: "<name>" for scalars, "<name>_x" etc. for vectors.
/// @throws std::out_of_range if k is not in [0, components.size()).
std::string SensorValueLabel(const SensorDescription& s, int k);

}  // namespace penumbra
