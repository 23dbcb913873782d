// libFuzzer target: the policy controller's per-step checks (control/policy_action.h,
// control/policy_observation.h): arbitrary float32 outputs through ProcessPolicyOutputs with
// an arbitrary clip, and the naming of an arbitrary observation element for arbitrary term
// layouts. input: byte 0 the number of outputs (0 .. 63), byte 1 the clip choice, bytes 2..9
// the step, then term layouts (kind, size, history: 3 bytes each, count in byte 10) and the
// output floats. the documented failure is Error; an accepted output that is not finite, is
// larger than the clip or kPolicyMaxAbsAction, a crash or a sanitizer report is a finding.
// docs/fuzzing.md.

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <optional>
#include <string>
#include <vector>

#include "penumbra/control/policy_action.h"
#include "penumbra/control/policy_observation.h"
#include "penumbra/core/error.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace penumbra;
  if (size < 11) return 0;
  const size_t n = data[0] % 64;
  std::optional<double> clip;
  const uint8_t c = data[1];
  if (c % 4 == 1) clip = 100.0;
  if (c % 4 == 2) clip = kPolicyMaxAbsAction;
  if (c % 4 == 3) clip = 1e-3 * (c / 4 + 1);
  int64_t step;
  std::memcpy(&step, data + 2, 8);
  const size_t terms_n = data[10] % 16;
  size_t pos = 11;
  std::vector<ObservationTermConfig> terms;
  std::vector<int> sizes;
  for (size_t t = 0; t < terms_n && pos + 3 <= size; ++t, pos += 3) {
    ObservationTermConfig term;
    term.kind = static_cast<ObservationTermKind>(data[pos] % 8);
    term.history = 1 + data[pos + 2] % 8;
    terms.push_back(term);
    sizes.push_back(data[pos + 1] % 40);
  }
  std::vector<float> raw;
  for (; raw.size() < n && pos + 4 <= size; pos += 4) {
    float v;
    std::memcpy(&v, data + pos, 4);
    raw.push_back(v);
  }
  // naming any element, inside or past the terms, never fails
  for (size_t i = 0; i < raw.size(); ++i)
    if (DescribeObservationElement(terms, sizes, static_cast<int64_t>(i) * 7 - 3).empty())
      __builtin_trap();
  std::vector<std::string> joints(raw.size() / 2, "j");
  std::vector<double> action(raw.size(), 0.0);
  try {
    ProcessPolicyOutputs(raw, clip, step, 0.02 * static_cast<double>(step % 1000000), joints,
                         "fuzz", action);
    for (double a : action) {
      if (!std::isfinite(a) || std::abs(a) > kPolicyMaxAbsAction) __builtin_trap();
      if (clip && std::abs(a) > *clip) __builtin_trap();
    }
  } catch (const Error&) {
  }
  return 0;
}
