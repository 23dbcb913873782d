#include "penumbra/sensors/types/imu.h"

namespace penumbra {

std::vector<std::string_view> ImuSensorParams::Keys() { return {"preset", "noise"}; }

void ImuSensorParams::Read(const SensorParamReader& r) {
  if (r.Has("preset")) {
    std::vector<std::string_view> presets;
    for (const std::string& n : ImuPresetNames()) presets.push_back(n);
    preset = r.Enum("preset", presets);
  }
  if (r.Has("noise")) {
    const auto n = r.Map("noise", {"accel_noise_density", "accel_random_walk", "gyro_noise_density",
                                   "gyro_random_walk"});
    if (n->Has("accel_noise_density")) accel_noise_density = n->Noise("accel_noise_density");
    if (n->Has("accel_random_walk")) accel_random_walk = n->Noise("accel_random_walk");
    if (n->Has("gyro_noise_density")) gyro_noise_density = n->Noise("gyro_noise_density");
    if (n->Has("gyro_random_walk")) gyro_random_walk = n->Noise("gyro_random_walk");
  }
}

ImuNoiseConfig ImuSensorParams::MakeNoise() const {
  ImuNoiseConfig nc = ImuPreset(preset);
  nc.accel_noise_density = accel_noise_density.value_or(nc.accel_noise_density);
  nc.accel_random_walk = accel_random_walk.value_or(nc.accel_random_walk);
  nc.gyro_noise_density = gyro_noise_density.value_or(nc.gyro_noise_density);
  nc.gyro_random_walk = gyro_random_walk.value_or(nc.gyro_random_walk);
  return nc;
}

}  // namespace penumbra
