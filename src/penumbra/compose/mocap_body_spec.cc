#include "penumbra/compose/mocap_body_spec.h"

#include <cctype>
#include <cmath>
#include <set>

#include "penumbra/compose/mjcf_text.h"
#include "penumbra/core/error.h"

namespace penumbra {

void MocapBodySpec::ValidateOrThrow(size_t index) const {
  const std::string where =
      "mocap body spec " + std::to_string(index) + " ('" + SanitizeForMessage(name, 64) + "'): ";
  bool name_ok = !name.empty();
  for (char c : name)
    name_ok = name_ok && (std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-');
  if (!name_ok) throw Error(where + "name: expected a non-empty name of [A-Za-z0-9_-]");
  if (!(std::isfinite(height_m) && height_m > 0))
    throw Error(where + "height_m: got " + compose::FormatNumbers({height_m}) +
                "; expected a finite number > 0 (m)");
  if (height_m > 3)
    throw Error(where + "height_m: got " + compose::FormatNumbers({height_m}) +
                "; expected at most 3 (m)");
  for (const auto& [key, rgb] :
       {std::pair<const char*, const std::array<double, 3>*>{"shirt_rgb", &shirt_rgb},
        {"trousers_rgb", &trousers_rgb},
        {"skin_rgb", &skin_rgb}})
    for (double c : *rgb)
      if (!(c >= 0 && c <= 1))
        throw Error(where + key + ": got " + compose::FormatNumbers({c}) +
                    "; expected a channel in [0, 1]");
  if (!X_WB.matrix().allFinite()) throw Error(where + "X_WB: expected a finite pose");
}

void ValidateMocapBodySpecsOrThrow(const std::vector<MocapBodySpec>& specs) {
  std::set<std::string> names;
  for (size_t i = 0; i < specs.size(); ++i) {
    specs[i].ValidateOrThrow(i);
    if (!names.insert(specs[i].name).second)
      throw Error("mocap body spec " + std::to_string(i) + " ('" + specs[i].name +
                  "'): name: used by an earlier spec; expected unique names");
  }
}

}  // namespace penumbra
