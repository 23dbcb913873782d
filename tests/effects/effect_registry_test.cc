// the effects registry (effects/effect_types.h): every documented type is registered and
// every registered type is documented, each with its keys; the world reader, validation and
// the engine find types only through it.
#include <gtest/gtest.h>

#include <filesystem>
#include <regex>
#include <set>
#include <string>

#include "common/temp_dir.h"
#include "penumbra/effects/effect_config.h"
#include "penumbra/effects/effects_engine.h"

namespace penumbra {
namespace {

std::string ReadDoc(const std::string& name) {
  return testing::ReadAll(std::filesystem::path(PENUMBRA_SOURCE_DIR) / "docs" / name);
}

// the type names of the "### `<type>`" sections of docs/effects.md, in document order.
std::vector<std::string> DocumentedTypeSections(const std::string& doc) {
  std::vector<std::string> out;
  const std::regex heading(R"(\n### `([a-z_]+)`)");
  for (auto it = std::sregex_iterator(doc.begin(), doc.end(), heading);
       it != std::sregex_iterator(); ++it)
    out.push_back((*it)[1]);
  return out;
}

// the names listed in the `type` row of the "Keys of every effect" table.
std::vector<std::string> DocumentedTypeRow(const std::string& doc) {
  std::smatch m;
  const std::regex row(R"(\n\| `type` \| [^|]*\|[^|]*\| ([^\n]*) \|\n)");
  if (!std::regex_search(doc, m, row)) return {};
  const std::string cell = m[1];
  std::vector<std::string> out;
  const std::regex name("`([a-z_]+)`");
  for (auto it = std::sregex_iterator(cell.begin(), cell.end(), name); it != std::sregex_iterator();
       ++it)
    out.push_back((*it)[1]);
  return out;
}

TEST(EffectRegistry, ListsEveryDocumentedTypeInOrder) {
  const std::string doc = ReadDoc("effects.md");
  ASSERT_FALSE(doc.empty()) << "docs/effects.md not found";
  EXPECT_EQ(DocumentedTypeSections(doc), EffectTypeNames())
      << "docs/effects.md has one \"### `<type>`\" section per registered effect type";
  EXPECT_EQ(DocumentedTypeRow(doc), EffectTypeNames())
      << "the `type` row of docs/effects.md lists the registered types";
  // the order is part of the random-stream key: existing types keep their place
  const std::vector<std::string> first = {"fog",         "dust",       "smoke", "vdb_smoke",
                                          "fire",        "rain",       "snow",  "sparks",
                                          "light_event", "flashlight", "sun",   "wetness"};
  ASSERT_GE(EffectTypeNames().size(), first.size());
  EXPECT_EQ(
      std::vector<std::string>(EffectTypeNames().begin(), EffectTypeNames().begin() + first.size()),
      first);
}

TEST(EffectRegistry, EveryTypeKeyIsDocumentedAndDistinct) {
  const std::string doc = ReadDoc("effects.md");
  ASSERT_FALSE(doc.empty());
  const std::set<std::string_view> common = {"name",        "type",         "start_sec", "stop_sec",
                                             "fade_in_sec", "fade_out_sec", "region"};
  for (const EffectTypeInfo& t : EffectTypes()) {
    std::set<std::string_view> seen;
    for (std::string_view k : t.keys) {
      EXPECT_TRUE(seen.insert(k).second) << t.name << ": key " << k << " listed twice";
      EXPECT_FALSE(common.count(k)) << t.name << ": key " << k << " clashes with a common key";
      EXPECT_NE(doc.find("`" + std::string(k) + "`"), std::string::npos)
          << t.name << ": key " << k << " is not in docs/effects.md";
    }
  }
}

TEST(EffectRegistry, EntriesMatchTheVariant) {
  for (size_t i = 0; i < EffectTypes().size(); ++i) {
    const EffectTypeInfo& t = EffectTypes()[i];
    EXPECT_EQ(t.index, i);
    EXPECT_EQ(FindEffectType(t.name), &t);
  }
  EXPECT_EQ(FindEffectType("hail"), nullptr);
  EffectConfig e;
  EXPECT_EQ(e.type_name(), "fog");  // the default
  e.params = WetnessParams{};
  EXPECT_EQ(e.type_name(), "wetness");
  EXPECT_EQ(&e.type(), FindEffectType("wetness"));
  EXPECT_TRUE(e.Is<WetnessParams>());
  EXPECT_FALSE(e.Is<RainParams>());
  EXPECT_EQ(e.GetIf<RainParams>(), nullptr);
}

TEST(EffectRegistry, FluidStepOnlyForFluidEffects) {
  EffectConfig e;
  EXPECT_FALSE(EffectFluidDtSec(e));  // fog
  e.params = SmokeParams{};
  EXPECT_FALSE(EffectFluidDtSec(e));  // noise smoke
  e.Get<SmokeParams>().mode = SmokeParams::Mode::kPlume;
  e.Get<SmokeParams>().fluid.dt_sec = 0.05;
  EXPECT_EQ(EffectFluidDtSec(e), 0.05);
  e.params = FireParams{};
  EXPECT_EQ(EffectFluidDtSec(e), 1.0 / 30.0);
}

}  // namespace
}  // namespace penumbra
