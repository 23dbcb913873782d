#include "penumbra/world/world_file_document.h"

#include "penumbra/config/yaml_document.h"
#include "penumbra/core/error.h"
#include "penumbra/core/input_file.h"

namespace penumbra {

std::optional<ConfigValue> ReadWorldFileDocument(const std::string& world_file) {
  try {
    return ParseYaml(ReadInputFile(world_file, "world file"), world_file);
  } catch (const ConfigError&) {
    return std::nullopt;
  }
}

}  // namespace penumbra
