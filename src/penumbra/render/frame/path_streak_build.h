#pragma once
// the host side of the pathtraced tier's particle streaks on the GPU (path_streaks.h): per frame,
// the streaks of the CPU's ParticleStreaks (built for the camera without the realtime tier's
// per-pixel splat, rain precomputed: RealtimeFrameData::PrepareStreaks) as StreakPods in the
// leaf order of a BVH over their capsules' boxes (bvh_builder.h's binned SAH, WidenBvh), their
// particle sets and the rain's radiance, as the path kernels read them (PathStreaks over these
// host arrays; DevicePath::UploadStreaks copies them). the realtime tier's device splat takes
// the same StreakPods in index order without a BVH (BuildList; StreakSplatView).

#include <Eigen/Core>
#include <vector>

#include "penumbra/render/bvh/bvh_types.h"
#include "penumbra/render/frame/bvh_builder.h"
#include "penumbra/render/particles/particle_streaks.h"
#include "penumbra/render/transport/path_streaks.h"

namespace penumbra::cuda {

/// a frame's streaks and their BVH on the host.
class PathStreakBuild {
 public:
  /// builds from `streaks` (Built for the frame, PrecomputeRain called; empty: none) and the
  /// open sky's sphere-average radiance `sky_ambient` (cd/m^2); records the time it took. the
  /// BVH is built over `pool` (may be null; BuildBvh: the same bits either way).
  void Build(const ParticleStreaks& streaks, const Eigen::Vector3f& sky_ambient,
             ThreadPool* pool = nullptr);
  /// the streaks of `streaks` (Built for the frame; empty: none) in their index order
  /// (StreakPod::prim = the index), their particle sets and `sky_ambient`, without a BVH (View's
  /// nodes null) or rain radiance (the realtime tier's device splat, StreakSplatView, shades
  /// rain per pixel); records the time it took.
  void BuildList(const ParticleStreaks& streaks, const Eigen::Vector3f& sky_ambient);
  /// the particle sets of `streaks` (Built for the frame; none without a frame) and
  /// `sky_ambient` without any streak (empty() stays true): for streaks that stay where they
  /// were made (the device culling's), which ViewOver points at. the sets do not
  /// depend on the streaks (ParticleStreaks::SetPod reads the effects' particle sets only).
  void BuildSets(const ParticleStreaks& streaks, const Eigen::Vector3f& sky_ambient);
  /// this object's particle sets and sky_ambient over `num` StreakPods at `streaks` (index
  /// order, no BVH, no rain radiance; any memory: the device culling's buffer in place, where
  /// num may be a bound of their count, StreakSplatView::count).
  PathStreaks ViewOver(const StreakPod* streaks, int32_t num) const;
  /// *pods swapped in as the streaks, the sets kept (after BuildSets: the device culling's
  /// streaks copied to the host for a reader of View; *pods gets the old array).
  void SwapPods(std::vector<StreakPod>* pods) { pods_.swap(*pods); }
  /// no streaks (View's num 0).
  void Clear();
  /// the streaks over this object's arrays (valid until the next Build or Clear).
  PathStreaks View() const;
  bool empty() const { return pods_.empty(); }
  /// wall-clock milliseconds of the last Build (the pods, boxes, BVH and widening).
  double build_ms() const { return build_ms_; }

 private:
  std::vector<StreakPod> pods_;  // leaf order
  std::vector<StreakSetPod> sets_;
  std::vector<Float3> rain_;
  std::vector<BvhWideNode> nodes_;
  Blas root_;
  Float3 sky_ambient_;
  double build_ms_ = 0;
  // the pods of streaks in the order order[k] (null: index order), their sets and rain
  void FillPods(const ParticleStreaks& streaks, const int32_t* order);
  // reused between frames for their capacity
  std::vector<PrimBox> boxes_;
  std::vector<BvhNode> binary_;
  std::vector<int32_t> order_;
};

}  // namespace penumbra::cuda
