#include <embree3/rtcore.h>

#include "penumbra/render/renderer.h"

namespace penumbra {

std::string EmbreeVersion() { return RTC_VERSION_STRING; }

}  // namespace penumbra
