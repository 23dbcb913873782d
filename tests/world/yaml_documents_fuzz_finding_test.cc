// found by fuzz/world_fuzz.cc: the 7-byte world file ",sn\xd4 !:" made yaml-cpp 0.7's
// LoadAll return empty documents for ever (all memory taken within seconds); the documents are
// now counted in a bounded loop. a second document with content is still refused with its line.

#include <gtest/gtest.h>

#include <string>

#include "penumbra/core/error.h"
#include "penumbra/world/world_config.h"

namespace penumbra {
namespace {

std::string YamlDocsFindingError(const std::string& text, int* line) {
  try {
    ParseWorld(text, "w.yaml");
  } catch (const ConfigError& e) {
    *line = e.line();
    return e.what();
  }
  return "";
}

TEST(YamlDocumentsFuzzFinding, AnEndlessDocumentStreamIsReadBoundedly) {
  int line = -1;
  const std::string err = YamlDocsFindingError(std::string(",sn\xd4 !:", 7), &line);
  EXPECT_NE(err.find("w.yaml"), std::string::npos) << err;
  // a second document is still refused at its line; a trailing empty one is still fine
  line = -1;
  const std::string second = YamlDocsFindingError("seed: 1\n---\nseed: 2\n", &line);
  EXPECT_NE(second.find("a second YAML document"), std::string::npos) << second;
  EXPECT_EQ(line, 3);
  line = -1;
  EXPECT_EQ(YamlDocsFindingError("seed: 1\nduration_sec: 1\n---\n", &line), "");
}

}  // namespace
}  // namespace penumbra
