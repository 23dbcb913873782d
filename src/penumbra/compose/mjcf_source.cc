#include "penumbra/compose/mjcf_source.h"

#include <string>
#include <vector>

#include "penumbra/compose/mjcf_text.h"
#include "penumbra/core/error.h"

namespace penumbra::compose {
namespace {

using tinyxml2::XMLDocument;
using tinyxml2::XMLElement;

constexpr int kMaxIncludeDepth = 32;

// parses a file; syntax errors name the file and line tinyxml2 reports.
std::unique_ptr<XMLDocument> ParseFileOrThrow(const std::string& path, const std::string& what) {
  if (!FileExists(path)) {
    throw ConfigError(path, 0, "", what + " not found; expected an existing XML file");
  }
  auto doc = std::make_unique<XMLDocument>();
  if (doc->LoadFile(path.c_str()) != tinyxml2::XML_SUCCESS) {
    const char* msg = doc->ErrorStr();
    throw ConfigError(path, doc->ErrorLineNum(), "",
                      std::string("XML syntax error: ") + (msg ? msg : "unknown"));
  }
  if (doc->RootElement() == nullptr) {
    throw ConfigError(path, 0, "", "no XML root element; expected <mujoco> or <robot>");
  }
  return doc;
}

}  // namespace

std::unique_ptr<MjcfSource> MjcfSource::Load(
    const std::string& file, const std::function<std::string(const std::string&)>& urdf_to_mjcf) {
  std::unique_ptr<MjcfSource> src(new MjcfSource());
  src->file_ = NormalizePath(file);
  src->model_dir_ = DirName(src->file_);
  src->doc_ = ParseFileOrThrow(src->file_, "model file");

  const std::string root_name = src->doc_->RootElement()->Name();
  const bool urdf_ext =
      ToLower(file).size() >= 5 && ToLower(file).compare(ToLower(file).size() - 5, 5, ".urdf") == 0;
  if (root_name == "robot" || (urdf_ext && root_name != "mujoco")) {
    if (root_name != "robot") {
      throw ConfigError(src->file_, src->doc_->RootElement()->GetLineNum(), root_name,
                        "URDF root element is <" + root_name + ">; expected <robot>");
    }
    if (!urdf_to_mjcf) {
      throw ConfigError(
          src->file_, 0, "",
          "URDF model but no URDF converter was given (ComposeOptions::urdf_to_mjcf)");
    }
    const std::string mjcf = urdf_to_mjcf(src->file_);
    auto doc = std::make_unique<XMLDocument>();
    if (doc->Parse(mjcf.c_str(), mjcf.size()) != tinyxml2::XML_SUCCESS ||
        doc->RootElement() == nullptr || std::string(doc->RootElement()->Name()) != "mujoco") {
      throw ConfigError(src->file_, 0, "",
                        "the URDF converter returned text that is not an MJCF <mujoco> document");
    }
    src->doc_ = std::move(doc);
    src->from_urdf_ = true;
  } else if (root_name != "mujoco") {
    throw ConfigError(src->file_, src->doc_->RootElement()->GetLineNum(), root_name,
                      "unknown root element <" + root_name +
                          ">; expected <mujoco> (MJCF) or "
                          "<robot> (URDF)");
  }
  src->ExpandIncludes(src->doc_->RootElement());
  return src;
}

Origin MjcfSource::Where(const XMLElement* elem) const {
  if (elem == nullptr) return {file_, 0, 0};
  const auto it = origins_.find(elem);
  if (it != origins_.end()) return it->second;
  return {file_, from_urdf_ ? 0 : elem->GetLineNum(), 0};
}

void MjcfSource::Fail(const XMLElement* elem, const std::string& key,
                      const std::string& problem) const {
  const Origin o = Where(elem);
  std::string p = problem;
  if (from_urdf_) p += " (in the MJCF converted from this URDF)";
  throw ConfigError(o.file, o.line, key, p);
}

XMLElement* MjcfSource::CloneInto(const XMLElement* src, const std::string& src_file, int depth) {
  XMLElement* dst = doc_->NewElement(src->Name());
  for (const tinyxml2::XMLAttribute* a = src->FirstAttribute(); a; a = a->Next()) {
    dst->SetAttribute(a->Name(), a->Value());
  }
  origins_[dst] = Origin{src_file, src->GetLineNum(), depth};
  for (const XMLElement* c = src->FirstChildElement(); c; c = c->NextSiblingElement()) {
    dst->InsertEndChild(CloneInto(c, src_file, depth));
  }
  return dst;
}

void MjcfSource::ExpandIncludes(XMLElement* scope) {
  XMLElement* child = scope->FirstChildElement();
  while (child) {
    if (std::string(child->Name()) != "include") {
      ExpandIncludes(child);
      child = child->NextSiblingElement();
      continue;
    }
    // replace <include> by the children of the included file's root; the loop then
    // continues with the first inserted element, so nested includes expand too
    const Origin at = Where(child);
    const char* rel = child->Attribute("file");
    if (rel == nullptr || *rel == '\0') {
      Fail(child, "include.file", "missing attribute; expected the path of an XML file");
    }
    if (at.depth >= kMaxIncludeDepth) {
      Fail(child, "include.file",
           std::string("'") + rel + "' nests includes deeper than " +
               std::to_string(kMaxIncludeDepth) + " (include cycle?)");
    }
    // relative to the including file first, then to the main model file (MuJoCo 2.2.2)
    std::vector<std::string> candidates;
    if (IsAbsolutePath(rel)) {
      candidates.push_back(rel);
    } else {
      candidates.push_back(NormalizePath(JoinPath(DirName(at.file), rel)));
      candidates.push_back(NormalizePath(JoinPath(model_dir_, rel)));
    }
    std::string path;
    for (const auto& c : candidates) {
      if (FileExists(c)) {
        path = c;
        break;
      }
    }
    if (path.empty()) {
      std::string looked;
      for (const auto& c : candidates) looked += (looked.empty() ? "" : ", ") + c;
      Fail(child, "include.file",
           std::string("included file '") + rel + "' not found; looked for " + looked);
    }
    auto inc = ParseFileOrThrow(path, "included file");
    XMLElement* anchor = child;
    for (const XMLElement* c = inc->RootElement()->FirstChildElement(); c;
         c = c->NextSiblingElement()) {
      XMLElement* clone = CloneInto(c, path, at.depth + 1);
      scope->InsertAfterChild(anchor, clone);
      anchor = clone;
    }
    XMLElement* next = child->NextSiblingElement();
    scope->DeleteChild(child);
    child = next;
  }
}

}  // namespace penumbra::compose
