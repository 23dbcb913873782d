#pragma once
// where the viewer's page files are: beside the binary in a build tree (build/web), or
// installed (PREFIX/share/penumbra/web next to PREFIX/bin/penumbra).

#include <string>

namespace penumbra {

/// the viewer's web folder: $PENUMBRA_WEB_ROOT if set, else `<folder of the running
/// executable>/web`, else `<that folder>/../share/penumbra/web`; the first that holds
/// index.html.
/// @throws Error naming every folder tried when none holds index.html.
std::string FindWebRoot();

}  // namespace penumbra
