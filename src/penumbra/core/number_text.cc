#include "penumbra/core/number_text.h"

#include <cstdio>

namespace penumbra {

std::string FormatG(double v) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%g", v);
  return buf;
}

}  // namespace penumbra
