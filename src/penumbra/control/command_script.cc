#include "penumbra/control/command_script.h"

#include <cmath>
#include <sstream>

#include "penumbra/config/config_value.h"
#include "penumbra/control/param_limits.h"

namespace penumbra {
namespace command_script_detail {

std::vector<std::pair<double, ParamNode>> ReadTimedItems(ControllerParams& params,
                                                         const std::string& key) {
  std::vector<std::pair<double, ParamNode>> out;
  const ConfigValue* list = params.Raw(key);
  if (!list || list->IsNull()) return out;
  if (!list->IsSequence())
    params.Fail(key, "expected a list of timed commands, e.g. [{t: 0.0, ...}, {t: 1.5, ...}]");
  double last_t = 0;
  for (size_t i = 0; i < list->size(); ++i) {
    const std::string path = key + "[" + std::to_string(i) + "]";
    ParamNode item((*list)[i], path, params.context());
    if (!(*list)[i].IsMap())
      item.FailHere("expected a mapping with `t` (s) and the command's keys");
    const double t = item.Number("t", std::nullopt, 0, kMaxParamTimeSec);
    if (i > 0 && t < last_t) {
      std::ostringstream s;
      s << "got " << t << " s after " << last_t << " s at " << key << "[" << i - 1
        << "]; expected times that never decrease along the list";
      item.Fail("t", s.str());
    }
    last_t = t;
    out.emplace_back(t, std::move(item));
  }
  return out;
}

}  // namespace command_script_detail
}  // namespace penumbra
