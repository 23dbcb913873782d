#include "penumbra/core/cache_dir.h"

#include <cstdlib>
#include <filesystem>

namespace penumbra {

std::string DefaultCacheDir(const std::string& kind) {
  namespace fs = std::filesystem;
  if (const char* d = std::getenv("PENUMBRA_CACHE_DIR"); d && *d)
    return (fs::path(d) / kind).string();
  if (const char* d = std::getenv("XDG_CACHE_HOME"); d && *d)
    return (fs::path(d) / "penumbra" / kind).string();
  if (const char* d = std::getenv("HOME"); d && *d)
    return (fs::path(d) / ".cache" / "penumbra" / kind).string();
  return (fs::temp_directory_path() / "penumbra-cache" / kind).string();
}

}  // namespace penumbra
