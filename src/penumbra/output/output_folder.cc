#include "penumbra/output/output_folder.h"

#include <fmt/format.h>

#include <algorithm>
#include <set>
#include <system_error>
#include <utility>
#include <vector>

#include "penumbra/core/error.h"
#include "penumbra/core/output_file.h"
#include "penumbra/scene/image_kind.h"
#include "penumbra/sensors/sensor_types.h"

namespace penumbra {
namespace {

namespace fs = std::filesystem;

const std::set<std::string> kTopFiles = {
    "run.json",         "composed.xml",     "trajectory.csv",
    "camera_info.yaml", "camera_info.json", "semantic_classes.json",
    "rig.json",         "npc_map.png",      "npc_map.json"};
// the sensor types' folders of CSV files (a LiDAR's folder holds a folder per sensor)
const std::set<std::string> kSensorFolders = {std::string(ImuSensorParams::kOutputFolder),
                                              std::string(MujocoSensorParams::kOutputFolder),
                                              std::string(GroundTruthSensorParams::kOutputFolder)};
// image folders are the image kinds' folders (scene/image_kind.h)
bool IsImageFolder(const std::string& name) { return IsImageKindFolder(name); }

bool EndsWith(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() &&
         s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

// NNNNNN.png: at least 6 digits
bool IsFrameFile(const std::string& name) {
  if (!EndsWith(name, ".png") || name.size() < 10) return false;
  return std::all_of(name.begin(), name.end() - 4, [](char c) { return c >= '0' && c <= '9'; });
}

// scan_NNNNNN.pcd
bool IsScanFile(const std::string& name) {
  if (name.rfind("scan_", 0) != 0 || !EndsWith(name, ".pcd") || name.size() < 15) return false;
  return std::all_of(name.begin() + 5, name.end() - 4, [](char c) { return c >= '0' && c <= '9'; });
}

// a content-named file of the `meshes` folder (core/output_file.h WriteContentNamedFile):
// STEM-<16 hex digits>.stl / .msh / .xml / .hfield: STL meshes converted from a URDF's
// COLLADA and other meshes, MuJoCo .msh meshes, the MJCF models of mesh models and their
// collision height fields (assets/mesh_model.h, assets/mjcf_mesh_conversion.h); the
// `environments` folder holds the same kind of files: generated environments' models and
// terrain height fields (session/session.cc)
bool IsMeshFile(const std::string& name) {
  const size_t dot = name.rfind('.');
  if (dot == std::string::npos) return false;
  const std::string ext = name.substr(dot);
  if (ext != ".stl" && ext != ".msh" && ext != ".xml" && ext != ".hfield") return false;
  if (dot < 18 || name[dot - 17] != '-') return false;
  return std::all_of(name.begin() + static_cast<std::ptrdiff_t>(dot - 16),
                     name.begin() + static_cast<std::ptrdiff_t>(dot),
                     [](char c) { return (c >= '0' && c <= '9') || (c >= 'a' && c <= 'f'); });
}

enum class Kind { kTop, kCameraFolder, kImageFolder, kLidarFolder, kSensorFolder, kMeshFolder };

class Scanner {
 public:
  Scanner(const fs::path& root, size_t limit) : root_(root), limit_(limit) {}

  // checks the entries of folder `dir` of kind `kind` (root_ itself is kTop)
  void Folder(const fs::path& dir, Kind kind) {
    std::error_code ec;
    for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
      if (found.size() >= limit_) return;
      const fs::path p = it->path();
      const std::string name = p.filename().string();
      const fs::file_status st = it->symlink_status(ec);
      if (ec) break;
      if (fs::is_symlink(st)) {
        Foreign(p, " (a symbolic link)");
        continue;
      }
      const bool dir_entry = fs::is_directory(st), file = fs::is_regular_file(st);
      if (file && IsTemporaryOutputName(name)) continue;
      switch (kind) {
        case Kind::kTop:
          if (file && kTopFiles.count(name)) continue;
          if (file && EndsWith(name, ".plog")) continue;  // a run log (--record)
          if (dir_entry) {
            Folder(p, name == LidarSensorParams::kOutputFolder     ? Kind::kLidarFolder
                      : name == "meshes" || name == "environments" ? Kind::kMeshFolder
                      : kSensorFolders.count(name)                 ? Kind::kSensorFolder
                                                                   : Kind::kCameraFolder);
            continue;
          }
          if (!file) {
            Foreign(p, " (not a file or folder)");
            continue;
          }
          break;
        case Kind::kCameraFolder:
          if (file && (name == "intrinsics.json" || name == "frames.csv")) continue;
          if (dir_entry) {
            Folder(p, IsImageFolder(name) ? Kind::kImageFolder : Kind::kCameraFolder);
            continue;
          }
          break;
        case Kind::kImageFolder:
          if (file && IsFrameFile(name)) continue;
          break;
        case Kind::kLidarFolder:
          if (file && (name == "index.csv" || IsScanFile(name))) continue;
          if (dir_entry) {
            Folder(p, Kind::kLidarFolder);
            continue;
          }
          break;
        case Kind::kMeshFolder:
          if (file && IsMeshFile(name)) continue;
          break;
        case Kind::kSensorFolder:
          if (file && EndsWith(name, ".csv")) continue;
          if (dir_entry) {
            Folder(p, Kind::kSensorFolder);
            continue;
          }
          break;
      }
      Foreign(p, "");
    }
    if (ec) throw Error("cannot list '" + dir.string() + "': " + ec.message());
  }

  // the top level of the output folder
  void Top() { Folder(root_, Kind::kTop); }

  std::vector<std::string> found;

 private:
  void Foreign(const fs::path& p, const std::string& why) {
    found.push_back(p.lexically_relative(root_).string() + why);
  }
  fs::path root_;
  size_t limit_;
};

std::string Quoted(const std::vector<std::string>& names) {
  std::string s;
  for (size_t i = 0; i < names.size(); ++i) s += (i ? ", '" : "'") + names[i] + "'";
  return s;
}

}  // namespace

std::vector<std::string> ForeignOutputEntries(const fs::path& out, size_t limit) {
  Scanner s(out, limit);
  s.Top();
  std::sort(s.found.begin(), s.found.end());
  return s.found;
}

void RefuseOutputFolderHoldingLog(const std::string& out_dir, const std::string& log_path) {
  // --force empties the output folder: never the one that holds the log being replayed
  std::error_code ec;
  const fs::path log = fs::weakly_canonical(log_path, ec);
  const fs::path out = fs::weakly_canonical(out_dir, ec);
  const std::string rel = log.lexically_relative(out).string();
  if (!ec && !rel.empty() && rel.rfind("..", 0) != 0)
    throw ConfigError("", 0, "--out",
                      "'" + out_dir + "' holds the log being replayed (" + log_path +
                          "); expected another output folder");
}

OutputLock PrepareOutputFolder(const fs::path& out, bool force, const std::string& key) {
  auto fail = [&](const std::string& what) {
    return ConfigError("", 0, key, "output folder '" + out.string() + "' " + what);
  };
  std::error_code ec;
  if (!fs::exists(fs::status(out, ec))) {
    try {
      CreateOutputFolder(out);
    } catch (const Error& e) {
      throw fail(std::string("cannot be created: ") + e.what());
    }
  }
  if (!fs::is_directory(fs::status(out, ec))) throw fail("exists and is not a folder");
  // one run per folder: locked before anything in it is looked at or removed
  OutputLock lock = LockOutputFolder(out, key);
  std::vector<std::string> entries;
  for (fs::directory_iterator it(out, ec), end; !ec && it != end; it.increment(ec))
    entries.push_back(it->path().filename().string());
  if (ec) throw fail("cannot be listed: " + ec.message());
  if (entries.empty()) return lock;
  if (!force) {
    std::sort(entries.begin(), entries.end());
    const size_t n = entries.size();
    if (n > 5) entries.resize(5);
    throw fail("is not empty (it holds " + Quoted(entries) + (n > 5 ? ", ..." : "") +
               "); choose an empty or new folder, or pass --force to replace the outputs of an "
               "earlier run");
  }
  const std::vector<std::string> foreign = ForeignOutputEntries(out, 10);
  if (!foreign.empty()) {
    throw fail("holds files that Penumbra did not write: " + Quoted(foreign) +
               (foreign.size() == 10 ? ", ..." : "") +
               "; --force removes only the outputs of an earlier run (README \"Outputs\"): move "
               "these away or choose another folder");
  }
  // only Penumbra outputs and no links (checked above): remove them
  std::vector<fs::path> top;
  for (fs::directory_iterator it(out, ec), end; !ec && it != end; it.increment(ec))
    top.push_back(it->path());
  if (ec) throw fail("cannot be listed: " + ec.message());
  for (const fs::path& p : top) {
    fs::remove_all(p, ec);
    if (ec) throw fail("cannot be cleared: '" + p.string() + "': " + ec.message());
  }
  return lock;
}

SetupRollback::SetupRollback(std::filesystem::path out, bool created)
    : out_(std::move(out)), created_(created) {}

SetupRollback::~SetupRollback() {
  if (done_) return;
  std::error_code ec;
  if (created_) {
    std::filesystem::remove_all(out_, ec);
    return;
  }
  std::vector<std::filesystem::path> entries;
  for (std::filesystem::directory_iterator it(out_, ec), end; !ec && it != end; it.increment(ec))
    entries.push_back(it->path());
  for (const std::filesystem::path& p : entries) std::filesystem::remove_all(p, ec);
}

}  // namespace penumbra
