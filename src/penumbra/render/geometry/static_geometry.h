#pragma once
// the static geometry the precomputed lighting structures bake (the sky irradiance volume,
// render/sky/sky_irradiance_volume.h, and the shelter map, render/particles/shelter_map.h): the
// geoms a RayQuery traces (render/ray_query.h) of the world body and of static bodies.

#include <Eigen/Core>
#include <string>
#include <vector>

#include "penumbra/core/pose.h"
#include "penumbra/scene/scene_description.h"

namespace penumbra {

/// axis-aligned bounds of a geom's shape in its own frame (m); false for planes (unbounded)
/// and for meshes / height fields that are missing or empty.
bool LocalHalfExtents(const SceneDescription& scene, const Geom& g, Eigen::Vector3d* lo,
                      Eigen::Vector3d* hi);

/// g is traced by a RayQuery: group <= 2 and its material (if any) has alpha >= 0.5.
/// @throws Error "<who>: geom 'name' refers to missing material N".
bool IsRayVisible(const SceneDescription& scene, const Geom& g, const std::string& who);

/// checks a traced geom's references (body, mesh, height field) and sizes (positive box and
/// analytic sizes, non-negative plane size). @throws Error "<who>: geom 'name' ..." naming it.
void ValidateRayGeom(const SceneDescription& scene, const Geom& g, const std::string& who);

/// checks a visible spatial tendon (SceneDescription::tendons): its material exists and its width
/// is positive and finite. @throws Error "<who>: tendon 'name' ..." naming it.
void ValidateRayTendon(const SceneDescription& scene, const Tendon& tendon, const std::string& who);

/// the traced geoms of a scene as the ray queries group them (RayScene, the CUDA BvhScene): the
/// first group holds every geom of the world body and of static bodies (body -1), then one group
/// per moving body in the order of its first geom. each geom is checked (IsRayVisible,
/// ValidateRayGeom). @throws Error as those, naming `who`.
struct RayGeomGroup {
  int body = -1;           ///< the moving body; -1 for the static group
  std::vector<int> geoms;  ///< indices into SceneDescription::geoms, ascending
};
std::vector<RayGeomGroup> GroupRayGeoms(const SceneDescription& scene, const std::string& who);

/// g is traced by a RayQuery (group <= 2, material alpha >= 0.5) and belongs to a static body.
bool IsStaticVisible(const SceneDescription& scene, const Geom& g);

/// body b is the world body or marked Body::is_static.
bool IsStaticBody(const SceneDescription& scene, int b);

/// `scene` with only its static visible geoms (IsStaticVisible), and in *lo_W, *hi_W the world
/// frame axis-aligned bounds (m) of the finite ones posed by X_WB (one pose per body; planes
/// and empty meshes are left out of the bounds). with no finite static geom, *lo_W = +inf and
/// *hi_W = -inf (lo > hi).
SceneDescription StaticGeoms(const SceneDescription& scene, const std::vector<Pose>& X_WB,
                             Eigen::Vector3d* lo_W, Eigen::Vector3d* hi_W);

}  // namespace penumbra
