// tests of config/yaml_document.h: the tree and its lines, and every refusal (syntax, a second
// document, tags, alias bombs) as a ConfigError naming the file and line.

#include "penumbra/config/yaml_document.h"

#include <gtest/gtest.h>

#include <string>

#include "penumbra/core/error.h"

namespace penumbra {
namespace {

// the ConfigError ParseYaml throws on `text`
ConfigError YamlDocumentErrorOf(const std::string& text) {
  try {
    ParseYaml(text, "f.yaml");
  } catch (const ConfigError& e) {
    return e;
  }
  ADD_FAILURE() << "no ConfigError for " << text;
  return ConfigError("", 0, "", "none");
}

TEST(YamlDocument, BuildsTheTreeWithLines) {
  const ConfigValue v = ParseYaml("a: 1\nb:\n  - x\n  - 'y'\nc:\n", "f.yaml");
  ASSERT_TRUE(v.IsMap());
  ASSERT_EQ(v.size(), 3u);
  EXPECT_EQ(v["a"].Scalar(), "1");
  EXPECT_EQ(v.entries()[1].key_line, 2);
  EXPECT_TRUE(v["b"].IsSequence());
  EXPECT_EQ(v["b"][0].line(), 3);
  EXPECT_FALSE(v["b"][0].IsQuoted());
  EXPECT_TRUE(v["b"][1].IsQuoted());
  EXPECT_TRUE(v["c"].IsNull());
  EXPECT_FALSE(v["d"].IsDefined());
  EXPECT_TRUE(ParseYaml("", "f.yaml").IsNull());
}

TEST(YamlDocument, RefusesSyntaxErrorsTagsAndSecondDocuments) {
  ConfigError e = YamlDocumentErrorOf("a: [1, 2\nb: 3\n");
  EXPECT_EQ(e.file(), "f.yaml");
  EXPECT_NE(e.problem().find("YAML syntax error"), std::string::npos) << e.what();
  e = YamlDocumentErrorOf("a: 1\nb: !foo 3\n");
  EXPECT_EQ(e.line(), 2);
  EXPECT_NE(e.problem().find("YAML tag '!foo' is not supported"), std::string::npos);
  e = YamlDocumentErrorOf("a: 1\n---\nb: 2\n");
  EXPECT_EQ(e.line(), 3);
  EXPECT_NE(e.problem().find("a second YAML document"), std::string::npos);
  YamlParseOptions first_only;
  first_only.single_document = false;
  EXPECT_EQ(ParseYaml("a: 1\n---\nb: 2\n", "f.yaml", first_only)["a"].Scalar(), "1");
}

TEST(YamlDocument, RefusesAnAliasBomb) {
  // 10 levels of 10 aliases each: 10^10 values once expanded
  std::string text = "a0: &a0 [x, x, x, x, x, x, x, x, x, x]\n";
  for (int i = 1; i <= 10; ++i) {
    const std::string p = "*a" + std::to_string(i - 1);
    text += "a" + std::to_string(i) + ": &a" + std::to_string(i) + " [";
    for (int k = 0; k < 10; ++k) text += (k ? ", " : "") + p;
    text += "]\n";
  }
  const ConfigError e = YamlDocumentErrorOf(text);
  EXPECT_NE(e.problem().find("expands to more than"), std::string::npos) << e.what();
}

TEST(YamlDocument, NoLineLiesPastTheEndOfTheFile) {
  // yaml-cpp marks the end of the input one line after the last one: an unclosed '[' or '{'
  // in a 3-line file was reported at line 4 (a 127-line world file's at line 129)
  ConfigError e = YamlDocumentErrorOf("a: 1\nb: [1,\n\n");
  EXPECT_NE(e.problem().find("YAML syntax error"), std::string::npos) << e.what();
  EXPECT_EQ(e.line(), 3) << e.what();
  e = YamlDocumentErrorOf("a: 1\nb: {x: 1\n# the end\n\n");
  EXPECT_EQ(e.line(), 4) << e.what();
  // a last line without a newline counts
  e = YamlDocumentErrorOf("a: 1\nb: [1,");
  EXPECT_EQ(e.line(), 2) << e.what();
  // a null value takes the mark of what follows it (the next key, or the end of the input):
  // it has no line of its own, so readers name its key's line
  const ConfigValue v = ParseYaml("a:\n# note\n\nb: 2\nc:\n\n\n", "f.yaml");
  EXPECT_EQ(v["a"].line(), 0);
  EXPECT_EQ(v["c"].line(), 0);
  EXPECT_EQ(v.entries()[2].key_line, 5);
  // a document of comments only is a null root without a line (it used to be the line after
  // the file's last)
  EXPECT_EQ(ParseYaml("# one\n# two\n\n", "f.yaml").line(), 0);
}

}  // namespace
}  // namespace penumbra
