#include "penumbra/scene/sim_state.h"

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

std::string StateSizeMismatch(const SimState& state, const StateDims& dims) {
  std::string problem;
  ForEachStateField(
      [&](const StateFieldInfo& f, const auto& v) {
        const int64_t want = StateFieldSize(f, dims);
        if (problem.empty() && static_cast<int64_t>(v.size()) != want)
          problem = std::string(f.name) + " has " + std::to_string(v.size()) +
                    " entries; expected " + std::to_string(want);
      },
      state);
  return problem;
}

}  // namespace penumbra
