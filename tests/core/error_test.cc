// error messages stay printable and bounded whatever the input held.

#include "penumbra/core/error.h"

#include <gtest/gtest.h>

#include <string>

namespace penumbra {
namespace {

TEST(SanitizeForMessageTest, PrintableAndUtf8TextIsKept) {
  EXPECT_EQ(SanitizeForMessage("cameras[0].rate_hz = 30"), "cameras[0].rate_hz = 30");
  // valid UTF-8 (2, 3 and 4 byte sequences) passes through unchanged
  const std::string utf8 =
      "K\xC3\xBC"
      "che \xE6\x91\x84\xE5\x83\x8F \xF0\x9F\xA4\x96";
  EXPECT_EQ(SanitizeForMessage(utf8), utf8);
}

TEST(SanitizeForMessageTest, ControlAndInvalidBytesAreEscaped) {
  EXPECT_EQ(SanitizeForMessage(std::string("a\0b\x1b[2Jc\n", 9)), "a\\x00b\\x1b[2Jc\\x0a");
  // a lone continuation byte, a truncated sequence, an overlong form, a surrogate
  EXPECT_EQ(SanitizeForMessage("\x80"), "\\x80");
  EXPECT_EQ(SanitizeForMessage("\xE6\x91"), "\\xe6\\x91");
  EXPECT_EQ(SanitizeForMessage("\xC0\xAF"), "\\xc0\\xaf");
  EXPECT_EQ(SanitizeForMessage("\xED\xA0\x80"), "\\xed\\xa0\\x80");
  EXPECT_EQ(SanitizeForMessage("\x7f\xff"), "\\x7f\\xff");
}

TEST(SanitizeForMessageTest, LongTextKeepsHeadAndTailAndSaysHowMuchWasCut) {
  const std::string value = "BEGIN" + std::string(10'000'000, 'x') + "END";
  const std::string s = SanitizeForMessage(value, 512);
  EXPECT_LE(s.size(), 600u);
  EXPECT_EQ(s.rfind("BEGIN", 0), 0u);
  EXPECT_EQ(s.substr(s.size() - 3), "END");
  // the elided count plus what is shown equals the input
  const size_t open = s.find(" ... [");
  const size_t close = s.find(" bytes elided] ... ");
  ASSERT_NE(open, std::string::npos);
  ASSERT_NE(close, std::string::npos);
  const size_t elided = std::stoul(s.substr(open + 6, close - open - 6));
  const size_t shown = open + (s.size() - close - std::string(" bytes elided] ... ").size());
  EXPECT_EQ(elided + shown, value.size());
  // binary garbage is both escaped and bounded (each byte may take 4 characters)
  const std::string garbage(100'000, '\x01');
  const std::string g = SanitizeForMessage(garbage, 512);
  EXPECT_LE(g.size(), 700u);
  EXPECT_EQ(g.find('\x01'), std::string::npos);
}

TEST(SanitizeForMessageTest, CutsNeverSplitAUtf8Sequence) {
  std::string value;
  for (int i = 0; i < 2000; ++i) value += "\xE6\x91\x84";  // 3-byte characters
  const std::string s = SanitizeForMessage(value, 100);
  EXPECT_EQ(s.find("\\x"), std::string::npos) << s;  // nothing became an escape
}

TEST(ConfigErrorTest, MessageIsSanitizedButProblemKeepsTheInput) {
  const std::string value(5'000'000, 'v');
  const ConfigError e("w.yaml", 3, "models[0].name", "'" + value + "\x07' is not a name");
  const std::string what = e.what();
  EXPECT_LT(what.size(), 1500u);
  EXPECT_EQ(what.rfind("w.yaml:3: models[0].name: 'vvv", 0), 0u) << what.substr(0, 80);
  EXPECT_NE(what.find("\\x07' is not a name"), std::string::npos);
  EXPECT_EQ(e.problem().size(), value.size() + 17);
  EXPECT_EQ(e.file(), "w.yaml");
  EXPECT_EQ(e.line(), 3);
  EXPECT_EQ(e.key(), "models[0].name");
  EXPECT_EQ(ConfigError("", 0, "--seed", "bad").what(), std::string("<command line>: --seed: bad"));
}

}  // namespace
}  // namespace penumbra
