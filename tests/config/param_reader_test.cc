// tests of config/param_reader.h over both backends: typed getters, ranges, the key path and
// file:line in every error, unused keys reported, and the same values from YAML and JSON.

#include "penumbra/config/param_reader.h"

#include <gtest/gtest.h>

#include <string>

#include "penumbra/config/json_document.h"
#include "penumbra/config/yaml_document.h"
#include "penumbra/core/error.h"

namespace penumbra {
namespace {

// the ConfigError `fn` throws (a failure when it throws none)
template <class Fn>
ConfigError ParamReaderErrorOf(Fn&& fn) {
  try {
    fn();
  } catch (const ConfigError& e) {
    return e;
  }
  ADD_FAILURE() << "no ConfigError";
  return ConfigError("", 0, "", "none");
}

TEST(ParamReader, ReadsTypedValuesFromYaml) {
  const ConfigValue doc = ParseYaml(
      "rate_hz: 30\nname: cam\non: yes\nxyz: [1, 2.5, -3]\nseed: 18446744073709551615\n"
      "mode: fast\nlist: [1, 2]\n",
      "w.yaml");
  ParamReader r(doc, "w.yaml", nullptr);
  EXPECT_EQ(r.Child("rate_hz").Double(), 30.0);
  EXPECT_EQ(r.Child("rate_hz").Int(), 30);
  EXPECT_EQ(r.Child("name").String(), "cam");
  EXPECT_TRUE(r.Child("on").Bool());
  EXPECT_EQ(r.Child("xyz").Vector3(), Eigen::Vector3d(1, 2.5, -3));
  EXPECT_EQ(r.Child("seed").Uint64(), 18446744073709551615ull);
  enum class Mode { kSlow, kFast };
  EXPECT_EQ(r.Child("mode").Enum<Mode>({{"slow", Mode::kSlow}, {"fast", Mode::kFast}}),
            Mode::kFast);
  EXPECT_EQ(r.Child("list").Doubles(), (std::vector<double>{1, 2}));
}

TEST(ParamReader, JsonAndYamlGiveTheSameValues) {
  const ConfigValue y = ParseYaml("a: 0.1\nb: [1, 2, 3]\nc: {d: true, e: text}\n", "x.yaml");
  const ConfigValue j = ParseJson(
      "{\"a\": 0.1,\n \"b\": [1, 2, 3],\n \"c\": {\"d\": true, \"e\": \"text\"}}", "x.json");
  for (const ConfigValue& doc : {y, j}) {
    ParamReader r(doc, "x", nullptr);
    EXPECT_EQ(r.Child("a").Double(), 0.1);
    EXPECT_EQ(r.Child("b").Vector3(), Eigen::Vector3d(1, 2, 3));
    EXPECT_TRUE(r.Child("c").Child("d").Bool());
    EXPECT_EQ(r.Child("c").Child("e").String(), "text");
    EXPECT_NO_THROW(r.ReportUnused());
  }
}

TEST(ParamReader, ErrorsNameFileLineAndKeyPath) {
  const ConfigValue doc =
      ParseYaml("cameras:\n  - name: a\n    rate_hz: fast\n    fov: 200\n", "w.yaml");
  ParamReader r(doc, "w.yaml", nullptr);
  const ParamReader cam = r.Child("cameras").Element(0);
  ConfigError e = ParamReaderErrorOf([&] { cam.Child("rate_hz").Double(); });
  EXPECT_EQ(e.file(), "w.yaml");
  EXPECT_EQ(e.line(), 3);
  EXPECT_EQ(e.key(), "cameras[0].rate_hz");
  EXPECT_EQ(e.problem(), "expected a number, got 'fast'");
  e = ParamReaderErrorOf([&] { cam.Child("fov").Double(1, 179, "deg"); });
  EXPECT_EQ(e.line(), 4);
  EXPECT_EQ(e.problem(), "got 200; expected a number in [1, 179] (deg)");
  e = ParamReaderErrorOf([&] { cam.Child("width"); });
  EXPECT_EQ(e.key(), "cameras[0].width");
  EXPECT_EQ(e.problem(), "required key 'width' is missing");
  e = ParamReaderErrorOf([&] { cam.Child("name").Int(0, 5); });
  EXPECT_EQ(e.problem(), "expected an integer, got 'a'");
}

TEST(ParamReader, JsonErrorsNameTheLine) {
  const ConfigValue doc = ParseJson("{\n  \"a\": 1,\n  \"b\": \"x\"\n}\n", "c.json");
  ParamReader r(doc, "c.json", nullptr);
  const ConfigError e = ParamReaderErrorOf([&] { r.Child("b").Double(); });
  EXPECT_EQ(e.line(), 3);
  EXPECT_EQ(e.key(), "b");
  EXPECT_EQ(e.problem(), "expected a number, got the quoted string \"x\"");
  const ConfigError syntax = ParamReaderErrorOf([] { ParseJson("{\n\"a\": 1,\n}", "s.json"); });
  EXPECT_EQ(syntax.file(), "s.json");
  EXPECT_EQ(syntax.line(), 3);
  EXPECT_NE(syntax.problem().find("JSON syntax error"), std::string::npos) << syntax.what();
}

TEST(ParamReader, ReportsUnusedKeysWithTheKeysAsked) {
  const ConfigValue doc =
      ParseYaml("physics:\n  timestep_sec: 0.002\n  integrater: RK4\n", "w.yaml");
  ParamReader r(doc, "w.yaml", nullptr);
  const ParamReader p = r.Child("physics");
  if (auto t = p.Find("timestep_sec")) {
    EXPECT_EQ(t->Double(), 0.002);
  }
  EXPECT_FALSE(p.Find("integrator").has_value());
  const ConfigError e = ParamReaderErrorOf([&] { p.ReportUnused(); });
  EXPECT_EQ(e.line(), 3);
  EXPECT_EQ(e.key(), "physics.integrater");
  EXPECT_EQ(e.problem(), "unknown key 'integrater'; expected one of: timestep_sec, integrator");
  EXPECT_NO_THROW(r.ReportUnused());  // `physics` was asked for
}

TEST(ParamReader, DuplicateKeysAndQuotedNumbersFail) {
  const ConfigValue doc = ParseYaml("a: 1\nb: \"2\"\na: 3\n", "d.yaml");
  ParamReader r(doc, "d.yaml", nullptr);
  ConfigError e = ParamReaderErrorOf([&] { r.ReportUnused(); });
  EXPECT_EQ(e.line(), 3);
  EXPECT_NE(e.problem().find("appears twice (first on line 1)"), std::string::npos);
  e = ParamReaderErrorOf([&] { r.Child("b").Double(); });
  EXPECT_EQ(e.problem(), "expected a number, got the quoted string \"2\"");
}

TEST(ParamReader, LineTableFindsTheClosestAncestor) {
  LineTable lines;
  const ConfigValue doc = ParseYaml("robots:\n  - name: r\n    pose:\n      xyz: [0, 0, 1]\n", "w");
  ParamReader r(doc, "w", &lines);
  r.Child("robots").Element(0).Child("pose").Child("xyz").Vector3();
  EXPECT_EQ(lines.Find("robots[0].pose.xyz"), 4);
  EXPECT_EQ(lines.Find("robots[0].pose.yaw_deg"), 3);
  EXPECT_EQ(lines.Find("robots[0].sensors"), 2);
}

}  // namespace
}  // namespace penumbra
