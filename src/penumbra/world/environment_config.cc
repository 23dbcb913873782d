#include "penumbra/world/environment_config.h"

#include "penumbra/config/param_reader.h"
#include "penumbra/core/error.h"

namespace penumbra {

const std::vector<std::string_view>& EnvironmentTypes() {
  static const std::vector<std::string_view> kTypes = {"house", "warehouse", "outdoor"};
  return kTypes;
}

void EnvironmentConfig::ValidateOrThrow(const std::string& file, int line,
                                        const std::string& key) const {
  bool known = false;
  for (std::string_view t : EnvironmentTypes()) known = known || t == type;
  if (!known)
    throw ConfigError(
        file, line, key + ".type",
        "'" + type + "' is not an environment type; expected house, warehouse or outdoor");
  if (texture_resolution < 16 || texture_resolution > 4096)
    throw ConfigError(file, line, key + ".texture_resolution",
                      std::to_string(texture_resolution) + "; expected 16 ... 4096");
}

EnvironmentConfig ReadEnvironmentConfig(const ParamReader& r) {
  r.ExpectMap({"type", "seed", "texture_resolution"});
  EnvironmentConfig c;
  c.type = r.Child("type").Enum(EnvironmentTypes());
  if (const auto found = r.Find("seed")) c.seed = found->Uint64();
  if (const auto found = r.Find("texture_resolution")) c.texture_resolution = found->Int();
  if (c.texture_resolution < 16 || c.texture_resolution > 4096)
    r.Child("texture_resolution")
        .Fail(std::to_string(c.texture_resolution) + "; expected 16 ... 4096");
  return c;
}

}  // namespace penumbra
