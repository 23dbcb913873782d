#pragma once
// the messages the viewer's server sends to the page (docs/viewer.md, "Messages"): the scene's
// geometry once per client, the world's moving state at the state rate, camera frames as
// binary messages. all JSON; poses as [x, y, z, qw, qx, qy, qz] (m, unit quaternion w first).

#include <nlohmann/json.hpp>
#include <string>

#include "penumbra/core/pose.h"
#include "penumbra/scene/scene_description.h"
#include "penumbra/scene/world_snapshot.h"

namespace penumbra {

/// [x, y, z, qw, qx, qy, qz] of `X` (translation m, unit quaternion).
nlohmann::json PoseJson(const Pose& X);

/// {"type": "scene", "bodies": [{"name", "parent", "static", "trail"}], "geoms": [{"body",
/// "shape" (plane|sphere|capsule|ellipsoid|cylinder|box|mesh|hfield), "size" [3] (MuJoCo
/// geom_size, m), "pos" [3], "quat" [4] (X_BG), "color" [r, g, b, a] (display sRGB 0..1),
/// "mesh", "hfield" (indices or -1)}], "meshes": [{"v": [3N], "f": [3F]}], "hfields": [{"rows",
/// "cols", "e" [rows cols], "size" [x, y, z, base]}], "center" [3], "extent"}: what the page's
/// 3D overview draws. geoms of MJCF groups > 2 and materials with alpha < 0.5 are left out
/// (invisible, as in the renderer); "trail" marks the root bodies of moving robots (free
/// bodies whose parent is the world). meshes are sent as floats with 4 significant decimals
/// (0.1 mm), which keeps a mesh-heavy scene's message a few MB at most.
nlohmann::json SceneJson(const SceneDescription& scene);

/// the pose of every camera of `scene` in `snapshot` (optical frame, OpenCV convention), by
/// camera name: {"front": [7], ...}. the snapshot must hold poses (SnapshotContent::kPoses).
nlohmann::json CameraPosesJson(const SceneDescription& scene, const WorldSnapshot& snapshot);

/// X_WB of every body of `snapshot` flattened: [7 x nbody].
nlohmann::json BodyPosesJson(const WorldSnapshot& snapshot);

/// a binary frame message: u32 little-endian length of `header` (JSON text), the header, then
/// `payload` (e.g. a JPEG file).
std::string PackFrameMessage(const nlohmann::json& header, const std::string& payload);

/// the header and payload of a PackFrameMessage result.
/// @throws Error for a message shorter than its header length says or whose header is not JSON.
std::pair<nlohmann::json, std::string> UnpackFrameMessage(const std::string& message);

}  // namespace penumbra
