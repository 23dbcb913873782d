#pragma once

#include <string>

namespace penumbra {

/// the linked MuJoCo library's version string (mj_versionString), e.g. "4.0.0".
std::string MujocoVersion();

}  // namespace penumbra
