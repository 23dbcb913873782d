#include "penumbra/physics/mujoco_version.h"

#include <mujoco/mujoco.h>

namespace penumbra {

std::string MujocoVersion() { return mj_versionString(); }

}  // namespace penumbra
