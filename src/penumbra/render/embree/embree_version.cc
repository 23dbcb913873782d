#include <embree3/rtcore.h>

#include "penumbra/render/embree/embree_renderer.h"

namespace penumbra {

std::string EmbreeVersion() { return RTC_VERSION_STRING; }

}  // namespace penumbra
