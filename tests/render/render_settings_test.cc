// tests of RenderSettings::ValidateOrThrow: every range bound is checked and the
// error names the world-file key path of the value.

#include "penumbra/render/render_settings.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "penumbra/core/error.h"

namespace penumbra {
namespace {

TEST(RenderSettingsTest, DefaultsAreValid) { EXPECT_NO_THROW(RenderSettings().ValidateOrThrow()); }

TEST(RenderSettingsTest, EachRangeIsChecked) {
  struct Case {
    void (*set)(RenderSettings*);
    const char* key;
    const char* expected;
  };
  const Case cases[] = {
      {[](RenderSettings* s) { s->samples_per_pixel = 65537; }, "render.samples_per_pixel",
       "expected [1, 65536]"},
      {[](RenderSettings* s) { s->max_bounces = 0; }, "render.max_bounces", "expected [1, 64]"},
      {[](RenderSettings* s) { s->threads = -1; }, "render.threads", "expected [0, 256]"},
      {[](RenderSettings* s) { s->max_anisotropy = 65; }, "render.max_anisotropy",
       "expected [1, 64]"},
      {[](RenderSettings* s) { s->ev100 = -11; }, "render.exposure.ev100", "expected [-10, 30]"},
      {[](RenderSettings* s) { s->exposure_compensation_ev = NAN; },
       "render.exposure.compensation_ev", "expected [-20, 20]"},
      {[](RenderSettings* s) { s->backend = static_cast<RenderSettings::Backend>(7); },
       "render.backend", "unknown backend; expected one of: cpu, cuda, auto (embree = cpu)"},
  };
  for (const Case& c : cases) {
    RenderSettings s;
    c.set(&s);
    try {
      s.ValidateOrThrow();
      ADD_FAILURE() << "no error for " << c.key;
    } catch (const ConfigError& e) {
      EXPECT_EQ(e.key(), c.key);
      EXPECT_EQ(e.file(), "");
      EXPECT_EQ(e.line(), 0);
      EXPECT_NE(std::string(e.what()).find(c.expected), std::string::npos) << e.what();
    }
  }
  RenderSettings edge;
  edge.samples_per_pixel = 65536;
  edge.max_bounces = 64;
  edge.threads = 256;
  edge.max_anisotropy = 1;
  edge.ev100 = 30;
  EXPECT_NO_THROW(edge.ValidateOrThrow());
}

}  // namespace
}  // namespace penumbra
