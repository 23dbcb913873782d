#pragma once

#include <string>

namespace penumbra {

/// the linked MuJoCo library's version string (mj_versionString), e.g. "2.2.2".
std::string MujocoVersion();

}  // namespace penumbra
