#include "penumbra/physics/urdf_meshes.h"

#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <tinyxml2.h>

#include <algorithm>
#include <assimp/Importer.hpp>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "penumbra/core/error.h"
#include "penumbra/core/input_file.h"
#include "penumbra/core/output_file.h"

namespace penumbra {
namespace {

namespace fs = std::filesystem;

std::string LowerExtension(const std::string& filename) {
  std::string ext = fs::path(filename).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext;
}

void AppendFloat(std::string* out, float v) {
  char b[4];
  std::memcpy(b, &v, 4);
  out->append(b, 4);
}

std::string ReadBytes(const fs::path& path) { return ReadInputFile(path, "URDF mesh file"); }

// the candidate paths of a URDF mesh filename, in lookup order (see the header).
std::vector<fs::path> MeshCandidates(const fs::path& urdf_dir, std::string f) {
  std::vector<fs::path> out;
  if (f.rfind("file://", 0) == 0) f = f.substr(7);
  if (f.rfind("package://", 0) == 0) {
    const std::string rest = f.substr(10);
    const size_t slash = rest.find('/');
    const std::string rel = slash == std::string::npos ? rest : rest.substr(slash + 1);
    out.push_back(urdf_dir / rel);
    out.push_back(urdf_dir.parent_path() / rel);
  } else if (fs::path(f).is_absolute()) {
    out.push_back(f);
  } else {
    out.push_back(urdf_dir / f);
  }
  out.push_back(urdf_dir / fs::path(f).filename());
  return out;
}

// replaces each quoted occurrence of `from` ("from" or 'from') in `text` by `to`.
void ReplaceQuoted(std::string* text, const std::string& from, const std::string& to) {
  for (const char q : {'"', '\''}) {
    const std::string a = q + from + q;
    const std::string b = q + to + q;
    for (size_t pos = text->find(a); pos != std::string::npos; pos = text->find(a, pos + b.size()))
      text->replace(pos, a.size(), b);
  }
}

}  // namespace

bool MujocoReadsMeshFile(const std::string& filename) {
  const std::string ext = LowerExtension(filename);
  return ext == ".stl" || ext == ".obj" || ext == ".msh";
}

std::string MeshFileToStl(const std::string& path) {
  Assimp::Importer importer;
  const aiScene* scene =
      importer.ReadFile(path, aiProcess_Triangulate | aiProcess_PreTransformVertices);
  if (scene == nullptr || scene->mRootNode == nullptr)
    throw Error("assimp could not import '" + path + "': " + importer.GetErrorString());
  const std::string ext = LowerExtension(path);
  const bool collada = ext == ".dae" || ext == ".zae";

  std::string body;
  uint32_t triangles = 0;
  for (unsigned i = 0; i < scene->mNumMeshes; ++i) {
    const aiMesh* mesh = scene->mMeshes[i];
    for (unsigned f = 0; f < mesh->mNumFaces; ++f) {
      const aiFace& face = mesh->mFaces[f];
      if (face.mNumIndices != 3) continue;  // points and lines
      aiVector3D v[3];
      for (int k = 0; k < 3; ++k) {
        const aiVector3D p = mesh->mVertices[face.mIndices[k]];
        // assimp's COLLADA importer made the scene y-up: back to z-up
        v[k] = collada ? aiVector3D(p.x, -p.z, p.y) : p;
      }
      aiVector3D n = (v[1] - v[0]) ^ (v[2] - v[0]);
      const float len = n.Length();
      n = len > 0.0f ? n / len : aiVector3D(0.0f, 0.0f, 0.0f);
      for (const aiVector3D& p : {n, v[0], v[1], v[2]}) {
        AppendFloat(&body, p.x);
        AppendFloat(&body, p.y);
        AppendFloat(&body, p.z);
      }
      body.append(2, '\0');
      ++triangles;
    }
  }
  if (triangles == 0)
    throw Error("assimp read '" + path + "' but found no triangles in it; expected a surface mesh");
  // a binary STL header must not start with "solid" (readers would take it for ASCII)
  std::string out = "penumbra: from " + fs::path(path).filename().string() + " via assimp";
  out.resize(80, '\0');
  char count[4];
  std::memcpy(count, &triangles, 4);
  out.append(count, 4);
  out += body;
  return out;
}

UrdfMeshConversion ConvertUrdfMeshes(const std::string& urdf_path, const std::string& urdf_text) {
  using tinyxml2::XMLElement;
  UrdfMeshConversion result{urdf_text, {}};
  tinyxml2::XMLDocument doc;
  if (doc.Parse(urdf_text.c_str(), urdf_text.size()) != tinyxml2::XML_SUCCESS) return result;
  const XMLElement* robot = doc.RootElement();
  if (robot == nullptr) return result;
  const fs::path urdf_dir = fs::absolute(fs::path(urdf_path)).parent_path();
  std::vector<std::string> done;
  for (const XMLElement* link = robot->FirstChildElement("link"); link;
       link = link->NextSiblingElement("link")) {
    const std::string link_name = link->Attribute("name") ? link->Attribute("name") : "";
    for (const char* part : {"visual", "collision"}) {
      for (const XMLElement* e = link->FirstChildElement(part); e;
           e = e->NextSiblingElement(part)) {
        const XMLElement* geometry = e->FirstChildElement("geometry");
        const XMLElement* mesh = geometry ? geometry->FirstChildElement("mesh") : nullptr;
        const char* filename = mesh ? mesh->Attribute("filename") : nullptr;
        if (filename == nullptr) continue;
        if (std::find(done.begin(), done.end(), filename) != done.end()) continue;
        const std::string what = "link '" + link_name + "' " + part + " mesh '" + filename + "': ";
        fs::path found;
        std::string looked;
        for (const fs::path& c : MeshCandidates(urdf_dir, filename)) {
          looked += (looked.empty() ? "" : ", ") + c.lexically_normal().string();
          if (found.empty() && fs::is_regular_file(c)) found = c.lexically_normal();
        }
        if (MujocoReadsMeshFile(filename)) {
          // MuJoCo reads it: named by the path found (package:// and bare names resolved)
          if (!found.empty()) ReplaceQuoted(&result.urdf, filename, found.string());
          done.push_back(filename);
          continue;
        }
        if (found.empty()) {
          throw ConfigError(urdf_path, mesh->GetLineNum(), "",
                            what + "file not found; looked for " + looked);
        }
        std::string stl;
        try {
          stl = MeshFileToStl(found.string());
        } catch (const Error& err) {
          throw ConfigError(urdf_path, mesh->GetLineNum(), "",
                            what + "MuJoCo reads only STL, OBJ and MSH and " + err.what());
        }
        char hash[17];
        std::snprintf(hash, sizeof(hash), "%016llx",
                      static_cast<unsigned long long>(Fnv1a64(ReadBytes(found))));
        const std::string name = found.stem().string() + "-" + hash + ".stl";
        ReplaceQuoted(&result.urdf, filename, name);
        result.files.emplace_back(name, std::move(stl));
        done.push_back(filename);
      }
    }
  }
  return result;
}

}  // namespace penumbra
