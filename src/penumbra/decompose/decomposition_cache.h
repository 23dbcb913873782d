#pragma once
// an on-disk cache of decompositions keyed by content: SHA-256 of the mesh (vertex
// coordinates and triangle indices as bytes), every option and kDecompositionVersion. a hit
// returns the stored parts bit for bit; entries are written to a temporary file and renamed,
// so a crash never leaves a half entry, and an unreadable entry counts as a miss.

#include <optional>
#include <string>

#include "penumbra/decompose/decomposition.h"

namespace penumbra {

/// bumped whenever the algorithm's output for the same input may change.
inline constexpr int kDecompositionVersion = 1;

/// the default cache folder: $PENUMBRA_CACHE_DIR/decompose, else
/// $XDG_CACHE_HOME/penumbra/decompose, else $HOME/.cache/penumbra/decompose, else
/// <temp>/penumbra-cache/decompose.
std::string DefaultDecompositionCacheDir();

/// 64 lowercase hex digits: the key of (mesh, options).
std::string DecompositionKey(const SolidMesh& mesh, const DecompositionOptions& options);

/// a cache folder (created on the first store).
class DecompositionCache {
 public:
  explicit DecompositionCache(std::string dir) : dir_(std::move(dir)) {}
  const std::string& dir() const { return dir_; }
  /// the file that holds `key`'s entry.
  std::string PathOf(const std::string& key) const;
  /// the stored decomposition, or nullopt when absent or unreadable.
  std::optional<Decomposition> Load(const std::string& key) const;
  /// stores `decomposition` under `key`. @throws Error naming the file when it cannot write.
  void Store(const std::string& key, const Decomposition& decomposition) const;

 private:
  std::string dir_;
};

/// how DecomposeCached got its result.
struct CachedDecomposition {
  Decomposition decomposition;
  bool cache_hit = false;
  std::string key;
};

/// DecomposeMesh through `cache`: a hit is loaded, a miss computed and stored.
/// @throws as DecomposeMesh and DecompositionCache::Store.
CachedDecomposition DecomposeCached(const SolidMesh& mesh, const DecompositionOptions& options,
                                    const DecompositionCache& cache,
                                    const std::string& name = "mesh");

}  // namespace penumbra
