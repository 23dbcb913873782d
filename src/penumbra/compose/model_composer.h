#pragma once
// one model's share of a composed scene: loads the model, rewrites it in place
// (names prefixed, angles in radians, euler as quat, top-level elements placed by
// the model pose, asset paths absolute, defaults isolated) and measures the sizes
// that keyframes need. scene_composer.cc merges the prepared models.
// internal to src/penumbra/compose.

#include <tinyxml2.h>

#include <array>
#include <functional>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "penumbra/compose/mjcf_defaults.h"
#include "penumbra/compose/mjcf_frames.h"
#include "penumbra/compose/mjcf_schema.h"
#include "penumbra/compose/mjcf_source.h"
#include "penumbra/core/pose.h"
#include "penumbra/world/world_config.h"

namespace penumbra::compose {

/// ordered attribute list (name, value).
using AttrList = std::vector<std::pair<std::string, std::string>>;

/// sets `name` to `value` in place when present, else appends it (keeps first-seen order).
void SetAttr(AttrList* list, const std::string& name, const std::string& value);

/// the value of `name` in `list`, or nullptr when absent.
const std::string* FindAttr(const AttrList& list, const std::string& name);

/// the merged <compiler> settings of one model.
struct CompilerInfo {
  bool degree = true;  ///< angle="degree" (MJCF default)
  std::string eulerseq = "xyz";
  std::string meshdir, texturedir, assetdir;
  bool strippath = false;
  AttrList other;        ///< every other attribute, last value wins, first-seen order
  AttrList lengthrange;  ///< <compiler><lengthrange> attributes
  const tinyxml2::XMLElement* first = nullptr;  ///< first <compiler> (for error lines)
};

/// sizes of the compiled model that keyframe vectors must match (MuJoCo mjModel nq, nv,
/// na, nu, nmocap) and the reference configuration, all after placement.
struct ModelSizes {
  int nq = 0, nv = 0, na = 0, nu = 0, nmocap = 0;
  std::vector<double> qpos0;                   ///< (nq)
  std::vector<double> mocap_pos;               ///< (3 nmocap) placed
  std::vector<double> mocap_quat;              ///< (4 nmocap) placed
  std::vector<std::pair<int, int>> free_dofs;  ///< (qpos address, qvel address) of free joints
  std::vector<bool> actuator_stateful;         ///< (nu) actuator has activation dynamics
  bool known = true;                           ///< false when the XML does not determine the sizes
  std::string why_unknown;
};

/// one <key> of the model, vectors as written (before composition).
struct KeyData {
  std::optional<std::string> name;
  std::optional<double> time;
  std::optional<std::vector<double>> qpos, qvel, act, ctrl, mpos, mquat;
  const tinyxml2::XMLElement* elem = nullptr;
};

class ModelComposer {
 public:
  /// loads the model file (URDF through `urdf_to_mjcf`), rewrites or rejects its MuJoCo-3
  /// keywords (mjcf_compat.h; the warnings are reported by Prepare) and reads its compiler
  /// settings.
  ModelComposer(const ModelConfig& config,
                const std::function<std::string(const std::string&)>& urdf_to_mjcf);

  const ModelConfig& config() const { return config_; }
  const std::string& prefix() const { return prefix_; }
  const MjcfSource& source() const { return *src_; }
  const CompilerInfo& compiler() const { return compiler_; }

  /// rewrites the model for composition (see scene_composer.h). `strip_inertials` drops
  /// <inertial> elements (inertiafromgeom="true" composed as "auto"). warnings are appended.
  void Prepare(bool strip_inertials, std::vector<std::string>* warnings);

  /// top-level section elements named `name` in document order (includes expanded).
  std::vector<tinyxml2::XMLElement*> Sections(const std::string& name) const;

  /// the prefixed root class name ("M/main").
  std::string RootClassName() const { return prefix_ + defaults_.root_name(); }
  const DefaultTree& defaults() const { return defaults_; }
  const ModelSizes& sizes() const { return sizes_; }
  const std::vector<KeyData>& keys() const { return keys_; }

  /// applies the model pose to a key's free-joint qpos/qvel and mocap poses.
  void PlaceKey(KeyData* key) const;

  /// largest `user` length of elements of MJCF type `tag_kind` ("body", "jnt", "geom",
  /// "site", "cam", "tendon", "actuator", "sensor"), defaults included.
  int MaxUserLength(const std::string& tag_kind) const;

 private:
  void AddFloatingBase();
  void CollectSections();
  void ReadCompiler();
  void CollectNames();
  void ProcessWorldbody(tinyxml2::XMLElement* parent, bool top, bool strip_inertials,
                        const Eigen::Vector3d& body_pos, const Eigen::Quaterniond& body_quat,
                        std::vector<std::string>* warnings);
  void ProcessElementFrame(tinyxml2::XMLElement* elem, bool top);
  void ProcessJoint(tinyxml2::XMLElement* joint, const Eigen::Vector3d& body_pos,
                    const Eigen::Quaterniond& body_quat);
  void StripDefaultOrientations();
  void CountActuators();
  void ResolveAssetPaths();
  void ReadKeys();
  void Rename();
  void AssignClasses();

  std::string ResolveRef(const tinyxml2::XMLElement* elem, const std::string& key, NameKind kind,
                         const std::string& value) const;
  OrientationSpec Orientation(const tinyxml2::XMLElement* elem, int cls, bool use_defaults) const;
  std::optional<std::vector<double>> Numbers(const tinyxml2::XMLElement* elem, const char* attr,
                                             const char* value, size_t count) const;
  std::string Key(const tinyxml2::XMLElement* elem, const char* attr) const;

  ModelConfig config_;
  std::string prefix_;
  std::unique_ptr<MjcfSource> src_;
  std::vector<std::pair<std::string, tinyxml2::XMLElement*>> sections_;
  CompilerInfo compiler_;
  DefaultTree defaults_;
  std::array<std::set<std::string>, kNumNameKinds> names_;
  std::vector<std::string> composite_prefixes_;
  bool has_composite_ = false;
  Pose X_WM_ = Pose::Identity();
  Eigen::Quaterniond q_WM_ = Eigen::Quaterniond::Identity();
  ModelSizes sizes_;
  std::vector<KeyData> keys_;
  std::vector<std::string> compat_warnings_;  ///< MuJoCo-3 keywords rewritten (mjcf_compat.h)
};

}  // namespace penumbra::compose
