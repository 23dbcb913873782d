#pragma once
// world-file IMUs become MuJoCo sensors: for every `type: imu` entry of the world's
// `sensors:` list, an accelerometer and a gyro (MJCF <accelerometer>, <gyro>) are added to
// the composed MJCF at the IMU's site:
//  - attached to a site with an identity pose: that site;
//  - otherwise a new site "penumbra_imu/<name>" in the attach body (or the site's body)
//    at X_BS = X_B,attach * X_attach,S (pos + quat);
// sensor names: "penumbra_imu/<name>/accel" and "penumbra_imu/<name>/gyro" (ImuSensorNames,
// sensors/mujoco_sensors.h).

#include <string>
#include <vector>

#include "penumbra/compose/scene_composer.h"
#include "penumbra/world/sensors_reader.h"

namespace penumbra {

/// adds the IMU sites and sensors of `sensors` (entries of other types are ignored) to
/// scene->document (in place).
/// @throws ConfigError(file, line, "<entry key>.body" / ".site", ...) naming the sensor when
///         the body or site does not exist in the composed model, or when a non-identity
///         pose is combined with a site oriented by anything other than pos/quat.
void AddImuSensors(const std::vector<SensorConfig>& sensors, ComposedScene* scene);

}  // namespace penumbra
