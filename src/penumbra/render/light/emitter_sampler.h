#pragma once
// next-event estimation for emissive geoms: geoms whose material has a non-zero emission
// (Material::emission, cd/m^2) are area lights that emit from both sides of their surface.
//
// one emitter is chosen per sample with probability proportional to its power (luminance of
// the emission x surface area), then a point on it:
//   sphere:                uniform direction in the cone the sphere subtends (seen from
//                          outside), pdf 1 / (2 pi (1 - cos theta_max)); from inside, by area.
//   box, mesh, cylinder,   uniform by area (faces / triangles / parts chosen by area,
//   capsule, finite plane: triangles by the square-root barycentric mapping), converted to
//                          solid angle with pdf_A d^2 / |cos theta_light|.
// (Pharr, Jakob, Humphreys, "Physically Based Rendering", 3rd ed., sec. 14.2 and 13.6.)
// ellipsoids, height fields and infinite planes are not sampled: they are found only by
// BSDF sampling, whose multiple-importance weight is then 1 (Pdf() returns 0 for them).
//
// the sampling arithmetic is the shared PB_HOST_DEVICE code of render/light/emitter_math.h (in
// double, rounded as the Eigen code it replaced); the geom's pose is composed here (Pose).
//
// visibility matches RayScene: geoms in MJCF groups > 2 or with material alpha < 0.5 are
// left out. emitters move with their bodies: every call takes the body poses X_WB.

#include <Eigen/Core>
#include <vector>

#include "penumbra/core/pose.h"
#include "penumbra/render/light/emitter_math.h"
#include "penumbra/scene/scene_description.h"

namespace penumbra {

/// a point sampled on an emissive geom, seen from a shading point.
struct EmitterSample {
  Eigen::Vector3f p_W{0, 0, 0};  ///< sampled point on the emitter, world frame, m
  Eigen::Vector3f n_W{0, 0, 1};  ///< unit outward surface normal there, world frame
  Eigen::Vector3f wi{0, 0, 1};   ///< unit direction from the shading point to p_W
  float distance = 0;            ///< |p_W - shading point|, m
  Eigen::Vector3f Le{0, 0, 0};   ///< emitted radiance towards the shading point, cd/m^2
  float pdf = 0;                 ///< solid-angle density of wi, emitter choice included
  int geom = -1;                 ///< index into SceneDescription::geoms
};

/// the emissive geoms of a scene. immutable after construction, thread-safe.
class EmitterSampler {
 public:
  /// collects the visible emissive geoms of `scene` (must outlive this object).
  /// @throws Error if an emissive mesh geom refers to a missing mesh.
  explicit EmitterSampler(const SceneDescription& scene);

  /// number of emissive geoms that can be sampled.
  int size() const { return static_cast<int>(emitters_.size()); }
  bool empty() const { return emitters_.empty(); }

  /// samples an emitter and a point on it as seen from p_W, with three uniform numbers in
  /// [0, 1) (u_pick chooses the emitter). X_WB: body poses by body index. returns false when
  /// there is nothing to sample or the sample has zero density (p_W on the emitter's plane).
  bool Sample(const std::vector<Pose>& X_WB, const Eigen::Vector3f& p_W, float u_pick, float u1,
              float u2, EmitterSample* s) const;

  /// solid-angle density with which Sample(), called at p_W, returns the direction to the
  /// point p_hit_W with unit normal n_hit_W on geom `geom` (any sign); 0 for geoms it never
  /// samples.
  float Pdf(const std::vector<Pose>& X_WB, int geom, const Eigen::Vector3f& p_W,
            const Eigen::Vector3f& p_hit_W, const Eigen::Vector3f& n_hit_W) const;

  /// emitter k (0 .. size() - 1, in pick order) as the shared functions take it (its pointers
  /// into this sampler's part cdf and the scene's mesh), its emitted radiance and its geom.
  const EmitterPod& pod(int k) const { return emitters_[k].pod; }
  const Eigen::Vector3f& Le(int k) const { return emitters_[k].Le; }
  int geom(int k) const { return emitters_[k].geom; }
  /// the cdf of the emitters' pick by power (size() + 1 values).
  const std::vector<double>& pick_cdf() const { return pick_cdf_; }
  /// per SceneDescription geom: its emitter index, or -1.
  const std::vector<int>& emitter_of_geom() const { return emitter_of_geom_; }
  /// the world pose of emitter k's geom for body poses X_WB.
  Pose EmitterPose(const std::vector<Pose>& X_WB, int k) const {
    return GeomPose(X_WB, emitters_[k]);
  }

 private:
  struct Emitter {
    int geom = -1;
    GeomShape shape = GeomShape::kSphere;
    Eigen::Vector3f Le{0, 0, 0};
    double area = 0;               // m^2
    std::vector<double> part_cdf;  // box faces / cylinder parts / mesh triangles, by area
    EmitterPod pod;                // the above as the shared functions take it
  };
  Pose GeomPose(const std::vector<Pose>& X_WB, const Emitter& e) const;

  const SceneDescription& scene_;
  std::vector<Emitter> emitters_;
  std::vector<double> pick_cdf_;      // over emitters_, by power
  std::vector<int> emitter_of_geom_;  // per geom: index into emitters_, or -1
};

}  // namespace penumbra
