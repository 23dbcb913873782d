#include "penumbra/viewer/web_root.h"

#include <cstdlib>
#include <filesystem>
#include <vector>

#include "penumbra/core/error.h"

namespace penumbra {

std::string FindWebRoot() {
  namespace fs = std::filesystem;
  std::vector<fs::path> tried;
  if (const char* env = std::getenv("PENUMBRA_WEB_ROOT"); env && *env) {
    tried.emplace_back(env);
  } else {
    std::error_code ec;
    const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
    if (!ec) {
      tried.push_back(exe.parent_path() / "web");
      tried.push_back(exe.parent_path().parent_path() / "share" / "penumbra" / "web");
    }
  }
  std::string list;
  for (const fs::path& p : tried) {
    std::error_code ec;
    if (fs::is_regular_file(p / "index.html", ec)) return p.lexically_normal().string();
    list += (list.empty() ? "" : ", ") + p.string();
  }
  throw Error("viewer: no web folder with index.html found (tried " + list +
              "); set PENUMBRA_WEB_ROOT to the build's or installation's web/ folder");
}

}  // namespace penumbra
