#include "penumbra/physics/mujoco_runtime.h"

#include <dlfcn.h>
#include <malloc.h>

#include <cstring>
#include <filesystem>
#include <memory>
#include <regex>

namespace penumbra {
namespace {

thread_local std::vector<std::string>* tls_warning_sink = nullptr;

void ThrowingErrorHandler(const char* msg) { throw MujocoError(msg ? msg : "unknown error"); }

void CapturingWarningHandler(const char* msg) {
  if (tls_warning_sink) tls_warning_sink->emplace_back(msg ? msg : "");
}

std::string Trim(std::string s) {
  while (!s.empty() && (s.back() == '\n' || s.back() == ' ' || s.back() == '\'')) s.pop_back();
  size_t b = 0;
  while (b < s.size() && (s[b] == '\n' || s[b] == ' ')) ++b;
  return s.substr(b);
}

// MuJoCo messages say "..., line 12", "Element 'geom', line 3" (XML errors) or
// "Object name = j, id = 0, line = 5, column = -1" (compiler errors)
int LineFromMessage(const std::string& msg) {
  static const std::regex re("line (?:= )?([0-9]+)");
  std::smatch m;
  if (std::regex_search(msg, m, re)) return std::stoi(m[1].str());
  return 0;
}

std::string OneLine(std::string s) {
  for (char& c : s)
    if (c == '\n') c = ' ';
  std::string out;
  for (char c : s)
    if (!(c == ' ' && !out.empty() && out.back() == ' ')) out += c;
  return out;
}

}  // namespace

std::string MujocoPluginDir() {
  Dl_info info{};
  if (dladdr(reinterpret_cast<const void*>(&mj_version), &info) == 0 || !info.dli_fname) return "";
  const std::filesystem::path dir = std::filesystem::path(info.dli_fname).parent_path() / "plugin";
  std::error_code ec;
  return std::filesystem::is_directory(dir, ec) ? dir.string() : std::string();
}

void InstallMujocoHandlers() {
  static std::once_flag once;
  std::call_once(once, [] {
    mju_user_error = ThrowingErrorHandler;
    mju_user_warning = CapturingWarningHandler;
    // MuJoCo's own plugins (mujoco.pid, mujoco.sensor.touch_grid, mujoco.sdf.*, ...), which
    // the wheel ships beside libmujoco, as MuJoCo's simulate loads them
    const std::string dir = MujocoPluginDir();
    if (!dir.empty()) mj_loadAllPluginLibraries(dir.c_str(), nullptr);
  });
}

std::vector<std::string>* SetMujocoWarningSink(std::vector<std::string>* sink) {
  std::vector<std::string>* old = tls_warning_sink;
  tls_warning_sink = sink;
  return old;
}

std::mutex& MujocoLoaderMutex() {
  static std::mutex mu;
  return mu;
}

mjModel* LoadMujocoXmlLocked(const std::string& path, const std::string* contents,
                             const std::string& display_name, std::vector<std::string>* warnings,
                             const std::vector<std::pair<std::string, std::string>>* extra_files) {
  InstallMujocoHandlers();
  if (!contents && !std::filesystem::exists(path))
    throw ConfigError(display_name, 0, "", "model file not found; expected an MJCF or URDF file");
  std::unique_ptr<mjVFS> vfs;
  if (contents) {
    vfs = std::make_unique<mjVFS>();
    mj_defaultVFS(vfs.get());
    std::vector<std::pair<std::string, std::string>> files;
    files.emplace_back(std::filesystem::path(path).filename().string(), std::string());
    if (extra_files) files.insert(files.end(), extra_files->begin(), extra_files->end());
    for (size_t i = 0; i < files.size(); ++i) {
      const std::string& name = files[i].first;
      const std::string& bytes = i == 0 ? *contents : files[i].second;
      if (mj_addBufferVFS(vfs.get(), name.c_str(), bytes.data(), static_cast<int>(bytes.size())) !=
          0) {
        mj_deleteVFS(vfs.get());
        throw ConfigError(display_name, 0, "",
                          "could not create the in-memory file '" + name + "' for MuJoCo");
      }
    }
  }
  char error[2048] = "";
  std::vector<std::string> loader_warnings;
  mjModel* m = nullptr;
  {
    const ScopedMujocoWarningSink sink(&loader_warnings);
    try {
      m = mj_loadXML(path.c_str(), vfs.get(), error, sizeof(error));
    } catch (const MujocoError& e) {
      if (vfs) mj_deleteVFS(vfs.get());
      throw ConfigError(display_name, 0, "",
                        std::string("MuJoCo could not load the model: ") + e.what());
    }
  }
  if (vfs) mj_deleteVFS(vfs.get());
  const std::string msg = Trim(error);
  if (!m) {
    throw ConfigError(display_name, LineFromMessage(msg), "",
                      "MuJoCo could not load the model: " + OneLine(msg));
  }
  if (warnings) {
    if (!msg.empty())
      warnings->push_back(display_name + ": MuJoCo compiler warning: " + OneLine(msg));
    for (const auto& w : loader_warnings)
      if (Trim(w) != msg)
        warnings->push_back(display_name + ": MuJoCo warning while loading: " + OneLine(Trim(w)));
  }
  return m;
}

void FreeLastXmlLocked() {
  mj_freeLastXML();
  malloc_trim(0);
}

}  // namespace penumbra
