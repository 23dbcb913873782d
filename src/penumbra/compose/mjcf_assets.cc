#include "penumbra/compose/mjcf_assets.h"

#include <tinyxml2.h>

#include <set>

#include "penumbra/compose/mjcf_text.h"
#include "penumbra/core/error.h"

namespace penumbra {

std::vector<MjcfAssetFile> MjcfAssetFiles(const std::string& mjcf_text,
                                          const std::string& base_dir) {
  tinyxml2::XMLDocument doc;
  if (doc.Parse(mjcf_text.c_str(), mjcf_text.size()) != tinyxml2::XML_SUCCESS)
    throw Error(std::string("MJCF asset list: the text is not well-formed XML: ") +
                (doc.ErrorStr() ? doc.ErrorStr() : "?"));
  std::vector<MjcfAssetFile> out;
  std::set<std::string> seen;
  const auto add = [&](const char* role, const char* value) {
    if (value == nullptr || *value == '\0') return;
    std::string p = value;
    if (!compose::IsAbsolutePath(p) && !base_dir.empty()) p = compose::JoinPath(base_dir, p);
    if (seen.insert(p).second) out.push_back({role, p});
  };
  const tinyxml2::XMLElement* root = doc.RootElement();
  if (root == nullptr) return out;
  for (const tinyxml2::XMLElement* sec = root->FirstChildElement("asset"); sec;
       sec = sec->NextSiblingElement("asset")) {
    for (const tinyxml2::XMLElement* a = sec->FirstChildElement(); a; a = a->NextSiblingElement()) {
      const std::string tag = a->Name();
      if (tag == "mesh" || tag == "skin" || tag == "hfield") {
        add(a->Name(), a->Attribute("file"));
      } else if (tag == "texture") {
        for (const char* attr :
             {"file", "fileright", "fileleft", "fileup", "filedown", "filefront", "fileback"})
          add("texture", a->Attribute(attr));
      }
    }
  }
  return out;
}

}  // namespace penumbra
