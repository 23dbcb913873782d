#include "penumbra/sensors/types/ground_truth.h"

namespace penumbra {

std::vector<std::string_view> GroundTruthSensorParams::Keys() { return {"bodies", "contacts"}; }

void GroundTruthSensorParams::Read(const SensorParamReader& r) {
  if (r.Has("contacts")) contacts = r.Boolean("contacts");
  if (r.Has("bodies")) bodies = r.Names("bodies");
}

}  // namespace penumbra
