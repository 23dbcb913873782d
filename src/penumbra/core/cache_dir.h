#pragma once
// where Penumbra keeps what it computes once and reuses across runs (convex decompositions,
// procedural material maps): one folder per kind under a common root.

#include <string>

namespace penumbra {

/// the cache folder of one kind `kind` (e.g. "decompose"): $PENUMBRA_CACHE_DIR/<kind>, else
/// $XDG_CACHE_HOME/penumbra/<kind>, else $HOME/.cache/penumbra/<kind>, else
/// <temp>/penumbra-cache/<kind>. the folder is not created here.
std::string DefaultCacheDir(const std::string& kind);

}  // namespace penumbra
