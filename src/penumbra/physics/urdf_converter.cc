#include "penumbra/physics/urdf_converter.h"

#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "penumbra/core/error.h"
#include "penumbra/core/input_file.h"
#include "penumbra/core/output_file.h"
#include "penumbra/physics/mujoco_runtime.h"
#include "penumbra/physics/urdf_meshes.h"

namespace penumbra {
namespace {

// inserts <mujoco><compiler .../></mujoco> right after the <robot ...> tag unless the
// URDF already has a <mujoco> element.
std::string WithImportOptions(const std::string& urdf) {
  if (urdf.find("<mujoco") != std::string::npos) return urdf;
  size_t pos = urdf.find("<robot");
  while (pos != std::string::npos) {
    const char next = pos + 6 < urdf.size() ? urdf[pos + 6] : '\0';
    if (next == ' ' || next == '>' || next == '\t' || next == '\n' || next == '\r') break;
    pos = urdf.find("<robot", pos + 6);
  }
  if (pos == std::string::npos) return urdf;  // MuJoCo reports the missing element
  char quote = 0;
  for (size_t i = pos; i < urdf.size(); ++i) {
    const char c = urdf[i];
    if (quote) {
      if (c == quote) quote = 0;
    } else if (c == '"' || c == '\'') {
      quote = c;
    } else if (c == '>') {
      if (urdf[i - 1] == '/') return urdf;  // empty robot
      return urdf.substr(0, i + 1) +
             "<mujoco><compiler discardvisual=\"false\" fusestatic=\"false\"/></mujoco>" +
             urdf.substr(i + 1);
    }
  }
  return urdf;
}

}  // namespace

std::string PrepareUrdfForMujoco(const std::string& urdf_path, const std::string& mesh_dir) {
  const std::string text = ReadInputFile(urdf_path, "URDF file");
  UrdfMeshConversion meshes = ConvertUrdfMeshes(urdf_path, text);
  const std::filesystem::path dir =
      mesh_dir.empty() ? std::filesystem::temp_directory_path() / "penumbra-urdf-meshes"
                       : std::filesystem::path(mesh_dir);
  std::string urdf = WithImportOptions(meshes.urdf);
  for (const auto& [name, bytes] : meshes.files) {
    const std::filesystem::path file = std::filesystem::absolute(dir / name);
    std::error_code ec;
    std::filesystem::create_directories(file.parent_path(), ec);
    WriteFileAtomic(file, bytes);
    for (const char q : {'"', '\''}) {
      const std::string from = q + name + q;
      const std::string to = q + file.string() + q;
      for (size_t pos = urdf.find(from); pos != std::string::npos;
           pos = urdf.find(from, pos + to.size()))
        urdf.replace(pos, from.size(), to);
    }
  }
  return urdf;
}

std::string ConvertUrdfToMjcfInto(const std::string& urdf_path, const std::string& mesh_dir) {
  const std::string text = ReadInputFile(urdf_path, "URDF file");
  // meshes MuJoCo cannot read become STL files: in memory for this load, on disk for the
  // composed model
  const UrdfMeshConversion meshes = ConvertUrdfMeshes(urdf_path, text);
  const std::string urdf = WithImportOptions(meshes.urdf);
  const std::filesystem::path dir =
      mesh_dir.empty() ? std::filesystem::temp_directory_path() / "penumbra-urdf-meshes"
                       : std::filesystem::path(mesh_dir);
  for (const auto& [name, bytes] : meshes.files) {
    const std::filesystem::path file = std::filesystem::absolute(dir / name);
    std::error_code ec;
    std::filesystem::create_directories(file.parent_path(), ec);
    WriteFileAtomic(file, bytes);
  }

  std::string tmpl = (std::filesystem::temp_directory_path() / "penumbra_urdf_XXXXXX").string();
  std::string mjcf;
  {
    std::lock_guard<std::mutex> lock(MujocoLoaderMutex());
    mjModel* m = LoadMujocoXmlLocked(urdf_path, &urdf, urdf_path, nullptr, &meshes.files);
    const int fd = mkstemp(tmpl.data());
    if (fd < 0) {
      mj_deleteModel(m);
      throw Error("ConvertUrdfToMjcf: cannot create a temporary file in " +
                  std::filesystem::temp_directory_path().string());
    }
    close(fd);
    char error[1024] = "";
    const int ok = mj_saveLastXML(tmpl.c_str(), m, error, sizeof(error));
    mj_deleteModel(m);
    if (!ok) {
      std::filesystem::remove(tmpl);
      throw Error("ConvertUrdfToMjcf: MuJoCo could not save " + urdf_path + " as MJCF: " + error);
    }
  }
  try {
    mjcf = ReadInputFile(tmpl, "MJCF file MuJoCo saved");
  } catch (...) {
    std::filesystem::remove(tmpl);
    throw;
  }
  std::filesystem::remove(tmpl);
  for (const auto& [name, bytes] : meshes.files) {
    const std::string from = "file=\"" + name + "\"";
    const std::string to = "file=\"" + std::filesystem::absolute(dir / name).string() + "\"";
    for (size_t pos = mjcf.find(from); pos != std::string::npos;
         pos = mjcf.find(from, pos + to.size()))
      mjcf.replace(pos, from.size(), to);
  }
  return mjcf;
}

std::string ConvertUrdfToMjcf(const std::string& urdf_path) {
  return ConvertUrdfToMjcfInto(urdf_path, "");
}

}  // namespace penumbra
