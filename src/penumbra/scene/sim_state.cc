#include "penumbra/scene/sim_state.h"

#include "penumbra/core/number_text.h"

namespace penumbra {

StateDims StateDimsOf(const SimState& state) {
  StateDims dims;
  ForEachStateField(
      [&dims](const StateFieldInfo& f, const auto& v) {
        dims[f.dim] = static_cast<int64_t>(v.size()) / f.per;
      },
      state);
  return dims;
}

std::string StateMismatch(const SimState& state, const StateDims& dims) {
  std::string problem;
  ForEachStateField(
      [&](const StateFieldInfo& f, const auto& v) {
        const int64_t want = StateFieldSize(f, dims);
        if (problem.empty() && static_cast<int64_t>(v.size()) != want)
          problem = std::string(f.name) + " has " + std::to_string(v.size()) +
                    " entries; expected " + std::to_string(want);
        if (!f.flag) return;
        for (size_t i = 0; i < v.size() && problem.empty(); ++i)
          if (v[i] != 0 && v[i] != 1)
            problem = std::string(f.name) + "[" + std::to_string(i) + "] is " +
                      FormatG(static_cast<double>(v[i])) + "; expected 0 or 1";
      },
      state);
  return problem;
}

}  // namespace penumbra
