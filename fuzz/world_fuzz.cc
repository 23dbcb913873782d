// libFuzzer target: the world file reader (world/world_config.h ParseWorld) on arbitrary YAML
// text. the documented failure is ConfigError; any other exception (a yaml-cpp exception that
// escaped, std::out_of_range, ...), a crash or a sanitizer report is a finding. the text is
// named as a file in the bundled worlds/ folder, so that the relative model paths of the seeds
// (worlds/*.yaml copies) resolve and the parser gets past them. docs/fuzzing.md.

#include <cstddef>
#include <cstdint>
#include <string>

#include "penumbra/core/build_info.h"
#include "penumbra/core/error.h"
#include "penumbra/world/world_config.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    penumbra::ParseWorld(text, PENUMBRA_SOURCE_DIR "/worlds/fuzz-input.yaml");
  } catch (const penumbra::ConfigError&) {
  }
  return 0;
}
