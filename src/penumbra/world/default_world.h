#pragma once
// where the bundled default world is: the world `penumbra bench` and the contact sheet use when
// given none.

#include <string>

namespace penumbra {

/// the bundled default world: worlds/default.yaml in the source tree (PENUMBRA_SOURCE_DIR,
/// core/build_info.h) when it exists there, else the relative path "worlds/default.yaml".
std::string DefaultWorldPath();

}  // namespace penumbra
