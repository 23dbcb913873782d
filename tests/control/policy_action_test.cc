// the per-step output checks of the policy controller (control/policy_action.h): a network
// output that is not finite or beyond kPolicyMaxAbsAction stops the run naming the step, the
// output and its joint; the clip applies to what passes.

#include "penumbra/control/policy_action.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "penumbra/core/error.h"

namespace penumbra {
namespace {

std::string OutputError(std::vector<float> raw, std::optional<double> clip = std::nullopt) {
  std::vector<double> action(raw.size());
  try {
    ProcessPolicyOutputs(raw, clip, 40, 0.2, {"q/a", "q/b", "q/c"}, "robots[q].controller", action);
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

TEST(PolicyActionTest, AHugeOutputStopsTheRunNamingStepAndJoint) {
  // 3e38 was accepted silently (and with a scale became an inf target)
  const std::string e = OutputError({0.1f, 3e38f, 0.0f});
  EXPECT_NE(e.find("robots[q].controller: policy step 40 (t = 0.2 s): output 1 (joint 'q/b') "
                   "is 3e+38"),
            std::string::npos)
      << e;
  EXPECT_NE(e.find("|value| <= 1e+06 (kPolicyMaxAbsAction"), std::string::npos) << e;
  // even with a clip: such an output means a broken network
  EXPECT_NE(OutputError({3e38f, 0, 0}, 100.0).find("output 0 (joint 'q/a')"), std::string::npos);
}

TEST(PolicyActionTest, NonFiniteOutputsStopTheRun) {
  const float inf = std::numeric_limits<float>::infinity();
  EXPECT_NE(OutputError({0, 0, -inf}).find("output 2 (joint 'q/c') is -inf"), std::string::npos);
  EXPECT_NE(OutputError({std::nanf(""), 0, 0}).find("output 0 (joint 'q/a') is nan"),
            std::string::npos);
}

TEST(PolicyActionTest, TheClipAppliesToAcceptedOutputs) {
  std::vector<float> raw = {-250.0f, 0.5f, 1e6f};
  std::vector<double> action(3);
  ProcessPolicyOutputs(raw, 100.0, 0, 0, {}, "p", action);
  EXPECT_EQ(action, (std::vector<double>{-100.0, 0.5, 100.0}));
  ProcessPolicyOutputs(raw, std::nullopt, 0, 0, {}, "p", action);
  EXPECT_EQ(action, (std::vector<double>{-250.0, 0.5, 1e6}));
}

}  // namespace
}  // namespace penumbra
