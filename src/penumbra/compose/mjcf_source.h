#pragma once
// one model file loaded for composition: parsed with tinyxml2, URDF converted to
// MJCF, <include> elements expanded, and the file/line every element came from
// remembered for error messages. internal to src/penumbra/compose.

#include <tinyxml2.h>

#include <functional>
#include <memory>
#include <string>
#include <unordered_map>

namespace penumbra::compose {

/// where an element was written: file and 1-based line (0 = unknown).
struct Origin {
  std::string file;
  int line = 0;
  int depth = 0;  ///< include nesting: 0 = the model file itself
};

class MjcfSource {
 public:
  /// loads `file` (MJCF, or URDF through `urdf_to_mjcf`) and expands its includes.
  /// @throws ConfigError for missing files, XML syntax errors (with line), a root element
  ///         that is neither <mujoco> nor <robot>, include cycles.
  static std::unique_ptr<MjcfSource> Load(
      const std::string& file, const std::function<std::string(const std::string&)>& urdf_to_mjcf);

  /// the <mujoco> root element (includes expanded).
  tinyxml2::XMLElement* root() const { return doc_->RootElement(); }
  tinyxml2::XMLDocument* doc() const { return doc_.get(); }
  /// absolute, normalized path of the model file.
  const std::string& file() const { return file_; }
  /// folder of the model file, ending in '/': base of relative asset paths (MuJoCo's
  /// modelfiledir; for URDF the URDF's folder).
  const std::string& model_dir() const { return model_dir_; }
  bool from_urdf() const { return from_urdf_; }

  /// file and line of `elem` (the included file for included elements).
  Origin Where(const tinyxml2::XMLElement* elem) const;

  /// throws ConfigError(file, line of elem, key, problem).
  [[noreturn]] void Fail(const tinyxml2::XMLElement* elem, const std::string& key,
                         const std::string& problem) const;

 private:
  MjcfSource() = default;
  void ExpandIncludes(tinyxml2::XMLElement* scope);
  tinyxml2::XMLElement* CloneInto(const tinyxml2::XMLElement* src, const std::string& src_file,
                                  int depth);

  std::unique_ptr<tinyxml2::XMLDocument> doc_;
  std::string file_;
  std::string model_dir_;
  bool from_urdf_ = false;
  std::unordered_map<const tinyxml2::XMLElement*, Origin> origins_;
};

}  // namespace penumbra::compose
