#pragma once
// conservative world-frame bounds of the moving bodies' geoms, for RayScene's static-only fast
// path: rays that provably miss every moving geom are traced against the static scene alone,
// which skips Embree's top level and the instances of the bodies near the rays (a camera on a
// robot starts every ray inside the bounds of the robot's own instances). the hits are those
// of the full scene, since nothing moving can be hit.
//
// bounds: every geom of a moving body is an oriented box in the body frame (analytic shapes:
// their half extents in the geom frame; triangle geoms: the axis-aligned box of their vertices
// in the body frame), and every body a sphere that holds its boxes. SetPose moves them into
// the world. every box and sphere is grown by a margin (kMarginM plus kMarginRel of its size
// and of its distance from the world origin) that covers float rounding in Embree and here.
//
// tests, both conservative (they may answer "may hit" for rays that miss, never the reverse):
//  - MayHit, for the rays of a RayCone (a tile of camera rays): a box entirely outside one of
//    the cone's planes (moved out by the cone's delta) misses every ray (separating plane, as
//    in view-frustum culling: Akenine-Moeller, Haines, Hoffman et al., "Real-Time Rendering",
//    4th ed., 2018, sec. 22.14), and so does a box beyond the plane through the apex normal
//    to one of its axes e when every ray direction makes an acute angle with e (the box of a
//    camera's housing right behind it, which the side planes of a tile off the optical axis
//    do not separate); a body whose sphere is outside one plane is skipped whole.
//  - SegmentsMayHit, for ray segments o + t d, t in [0, tmax] (tmax may be +inf): whether the
//    segment passes within a body sphere (closest point of the segment to the centre), tested
//    only for the segments that pass within the sphere of the body's cluster (all the bodies
//    of one robot).
//
// thread-safety: the tests are const and thread-safe; AddBody/SetPose are not.

#include <Eigen/Core>
#include <vector>

#include "penumbra/core/pose.h"
#include "penumbra/render/geometry/ray_cone.h"
#include "penumbra/render/ray.h"
#include "penumbra/render/shading_lanes.h"

namespace penumbra {

/// world-frame bounds of moving geoms and conservative ray tests against them (file comment).
class MovingBounds {
 public:
  /// absolute part of the margin that grows every bound, m.
  static constexpr float kMarginM = 1e-5f;
  /// relative part of the margin: this fraction of a bound's size and of its distance from the
  /// world origin (float rounding grows with both).
  static constexpr float kMarginRel = 1e-5f;

  /// an oriented box {c + axes x : |x|_inf <= 1}: centre and orthogonal half axes (columns,
  /// any length, zero for a flat box).
  struct Box {
    Eigen::Vector3f c{0, 0, 0};
    Eigen::Matrix3f axes = Eigen::Matrix3f::Zero();
  };

  /// adds a moving body whose geoms lie inside `boxes_B` (body frame), at the identity pose
  /// until SetPose. a body without boxes is never hit. `cluster`: any id shared by bodies that
  /// stay close together (e.g. the root body of a robot's kinematic tree), whose spheres are
  /// bounded by one sphere that SegmentsMayHit tests first. returns the body's index here.
  int AddBody(const std::vector<Box>& boxes_B, int cluster);

  /// poses body `body` (an index from AddBody) at X_WB. call CommitPoses before the tests.
  void SetPose(int body, const Pose& X_WB);

  /// recomputes the clusters' spheres after AddBody and SetPose calls.
  void CommitPoses();

  /// number of bodies added.
  int num_bodies() const { return static_cast<int>(bodies_.size()); }

  /// false only if no ray of `cone` can touch a moving geom (an invalid cone answers true,
  /// unless there are no moving geoms).
  bool MayHit(const RayCone& cone) const;

  /// the lanes among `active` whose segment o + t d, t in [0, tmax], may touch a moving geom
  /// (d non-zero; tmax >= 0, +inf allowed).
  LaneMask SegmentsMayHit(const Vec3Lanes& o, const Vec3Lanes& d, const Lanes& tmax,
                          const LaneMask& active) const;

 private:
  // a box with the margin that grows it (added to its projected radius).
  struct PaddedBox {
    Box box;
    float pad = 0;
  };
  struct Body {
    int cluster = 0;
    std::vector<PaddedBox> boxes_B;  // body frame
    Eigen::Vector3f sphere_c_B{0, 0, 0};
    float sphere_r = -1;  // incl. the margin; < 0: no boxes
  };
  std::vector<Body> bodies_;
  // world frame, by body: box_begin_[b] .. box_begin_[b + 1] index boxes_W_.
  std::vector<PaddedBox> boxes_W_;
  std::vector<int> box_begin_{0};
  std::vector<Eigen::Vector3f> sphere_c_W_;
  std::vector<float> sphere_r_W_;  // radius incl. the world-position margin; < 0: no boxes
  // per cluster id (in the order of first use): its bodies with boxes and their bounding sphere.
  struct Cluster {
    int id = 0;
    std::vector<int> bodies;
    Eigen::Vector3f c{0, 0, 0};
    float r = -1;
  };
  std::vector<Cluster> clusters_;
};

}  // namespace penumbra
