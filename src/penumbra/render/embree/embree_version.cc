#include "penumbra/render/embree/embree_version.h"

#include <embree3/rtcore.h>

namespace penumbra {

std::string EmbreeVersion() { return RTC_VERSION_STRING; }

}  // namespace penumbra
