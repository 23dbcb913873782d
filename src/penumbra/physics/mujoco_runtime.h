#pragma once
// process-wide glue around MuJoCo's global state (physics-internal):
//  - error and warning handlers: MuJoCo's defaults print, write MUJOCO_LOG.TXT and
//    call exit(1) on errors. penumbra installs handlers once per process that throw
//    MujocoError on errors (MuJoCo's own compiler throws through the engine the same
//    way) and route warning texts to the calling thread's sink, if any.
//  - the XML loader keeps global state (handlers swapped during compilation, the
//    "last loaded XML" used by mj_saveLastXML), so loads are serialised by a mutex.

#include <mujoco/mujoco.h>

#include <mutex>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "penumbra/core/error.h"

namespace penumbra {

/// an error reported by MuJoCo through mju_error (e.g. "Stack overflow").
class MujocoError : public PhysicsError {
 public:
  explicit MujocoError(const std::string& what) : PhysicsError(what) {}
};

/// installs penumbra's MuJoCo error/warning handlers and loads MuJoCo's own plugin libraries
/// (MujocoPluginDir) so that models using them load (once; thread-safe, idempotent).
void InstallMujocoHandlers();

/// the folder of MuJoCo's first-party plugin libraries shipped with the linked libmujoco (the
/// wheel's `mujoco/plugin/`: actuator, sensor and SDF plugins); "" when there is none.
std::string MujocoPluginDir();

/// sets the calling thread's sink for MuJoCo warning texts (nullptr = drop them).
/// returns the previous sink.
std::vector<std::string>* SetMujocoWarningSink(std::vector<std::string>* sink);

/// sets the calling thread's warning sink for its lifetime and restores the previous one.
class ScopedMujocoWarningSink {
 public:
  explicit ScopedMujocoWarningSink(std::vector<std::string>* sink)
      : previous_(SetMujocoWarningSink(sink)) {}
  ~ScopedMujocoWarningSink() { SetMujocoWarningSink(previous_); }
  ScopedMujocoWarningSink(const ScopedMujocoWarningSink&) = delete;
  ScopedMujocoWarningSink& operator=(const ScopedMujocoWarningSink&) = delete;

 private:
  std::vector<std::string>* previous_;
};

/// serialises MuJoCo's XML loader and mj_saveLastXML.
std::mutex& MujocoLoaderMutex();

/// loads an MJCF or URDF file with mj_loadXML. when `contents` is given, that text is
/// used instead of the file's (through a MuJoCo VFS), but assets still resolve
/// relative to `path`'s folder. the caller must hold MujocoLoaderMutex().
/// compiler warnings are appended to `warnings`. messages name the model `display_name`.
/// `extra_files` (name, bytes) join that in-memory file system (only with `contents`): an
/// asset whose file name (path stripped) is one of them is read from there.
/// @throws ConfigError(display_name, line from MuJoCo's message, "", MuJoCo's message).
mjModel* LoadMujocoXmlLocked(
    const std::string& path, const std::string* contents, const std::string& display_name,
    std::vector<std::string>* warnings,
    const std::vector<std::pair<std::string, std::string>>* extra_files = nullptr);

/// frees the "last loaded XML" that mj_loadXML keeps for mj_saveLastXML (MuJoCo's whole
/// compiler model: every mesh and texture a second time; sizes in docs/performance.md)
/// and returns the freed heap to the system (glibc malloc_trim). for loads that will not be
/// saved back; the caller must hold MujocoLoaderMutex().
void FreeLastXmlLocked();

}  // namespace penumbra
