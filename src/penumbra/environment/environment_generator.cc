#include "penumbra/environment/environment_generator.h"

#include "penumbra/core/error.h"
#include "penumbra/environment/house_generator.h"
#include "penumbra/environment/outdoor_generator.h"
#include "penumbra/environment/warehouse_generator.h"

namespace penumbra {

GeneratedEnvironment GenerateEnvironment(const EnvironmentConfig& config) {
  if (config.type == "house") return GenerateHouse(config.seed, config.texture_resolution);
  if (config.type == "warehouse") return GenerateWarehouse(config.seed, config.texture_resolution);
  if (config.type == "outdoor") return GenerateOutdoor(config.seed, config.texture_resolution);
  throw Error("unknown environment type '" + config.type +
              "'; expected house, warehouse or outdoor");
}

}  // namespace penumbra
