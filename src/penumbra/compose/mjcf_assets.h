#pragma once
// the files an MJCF document reads besides itself: meshes, skins, height fields and textures
// named by its <asset> elements (for the run log's asset hashes, runlog/run_log_format.h).

#include <string>
#include <vector>

namespace penumbra {

/// one file an MJCF document references.
struct MjcfAssetFile {
  std::string role;  ///< the element: "mesh", "skin", "hfield" or "texture"
  std::string path;  ///< as written, resolved against `base_dir` when relative
};

/// the asset files of MJCF text (e.g. the composed model, whose asset paths the composer made
/// absolute): `file` of every <mesh>, <skin>, <hfield> and the file, fileright, fileleft,
/// fileup, filedown, filefront, fileback of every <texture>, in document order, each path
/// once. relative paths are joined to `base_dir` (the compiler's meshdir / texturedir are not
/// applied: the composer has applied them already).
/// @throws Error when the text is not well-formed XML.
std::vector<MjcfAssetFile> MjcfAssetFiles(const std::string& mjcf_text,
                                          const std::string& base_dir = "");

}  // namespace penumbra
