#include "penumbra/sensors/types/mujoco.h"

namespace penumbra {

std::vector<std::string_view> MujocoSensorParams::Keys() { return {"sensors", "noise"}; }

void MujocoSensorParams::Read(const SensorParamReader& r) {
  if (r.Has("noise")) {
    const auto n = r.Map("noise", {"stddev"});
    if (n->Has("stddev")) stddev = n->Noise("stddev");
  }
  if (r.Has("sensors")) sensors = r.Names("sensors");
}

}  // namespace penumbra
