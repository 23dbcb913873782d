#include "penumbra/render/frame/path_streak_build.h"

#include <algorithm>
#include <chrono>
#include <cmath>

namespace penumbra::cuda {

void PathStreakBuild::Clear() {
  pods_.clear();
  sets_.clear();
  rain_.clear();
  nodes_.clear();
  root_ = Blas();
  build_ms_ = 0;
}

void PathStreakBuild::Build(const ParticleStreaks& streaks, const Eigen::Vector3f& sky_ambient,
                            ThreadPool* pool) {
  const auto t0 = std::chrono::steady_clock::now();
  Clear();
  sky_ambient_ = Float3{sky_ambient.x(), sky_ambient.y(), sky_ambient.z()};
  const int n = streaks.size();
  if (n == 0 || streaks.frame() == nullptr) return;
  const std::vector<Eigen::Vector4f>& ends = streaks.ends();
  // every capsule's box, padded for the float rounding of the slab test
  boxes_.resize(n);
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector4f& a = ends[2 * i];
    const Eigen::Vector4f& b = ends[2 * i + 1];
    PrimBox& box = boxes_[i];
    for (int k = 0; k < 3; ++k) {
      const float pad = a.w() * 1.0001f + 1e-6f * (1.0f + std::max(std::abs(a[k]), std::abs(b[k])));
      box.lo[k] = std::min(a[k], b[k]) - pad;
      box.hi[k] = std::max(a[k], b[k]) + pad;
    }
  }
  binary_.clear();
  order_.clear();
  BuildBvh(boxes_, 0, &binary_, &order_, pool);
  WidenBvh(binary_, &nodes_, &root_);
  FillPods(streaks, order_.data());
  for (const Eigen::Vector3f& L : streaks.rain_radiance())
    rain_.push_back(Float3{L.x(), L.y(), L.z()});
  build_ms_ =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

void PathStreakBuild::BuildList(const ParticleStreaks& streaks,
                                const Eigen::Vector3f& sky_ambient) {
  const auto t0 = std::chrono::steady_clock::now();
  Clear();
  sky_ambient_ = Float3{sky_ambient.x(), sky_ambient.y(), sky_ambient.z()};
  if (streaks.size() == 0 || streaks.frame() == nullptr) return;
  FillPods(streaks, nullptr);
  build_ms_ =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

void PathStreakBuild::BuildSets(const ParticleStreaks& streaks,
                                const Eigen::Vector3f& sky_ambient) {
  const auto t0 = std::chrono::steady_clock::now();
  Clear();
  sky_ambient_ = Float3{sky_ambient.x(), sky_ambient.y(), sky_ambient.z()};
  if (streaks.frame() == nullptr) return;
  const int num_sets = static_cast<int>(streaks.frame()->particles.size());
  for (int s = 0; s < num_sets; ++s) sets_.push_back(streaks.SetPod(s));
  build_ms_ =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

PathStreaks PathStreakBuild::ViewOver(const StreakPod* streaks, int32_t num) const {
  PathStreaks v;
  if (num <= 0 || streaks == nullptr) return v;
  v.num = num;
  v.streaks = streaks;
  v.sets = sets_.data();
  v.num_sets = static_cast<int32_t>(sets_.size());
  v.sky_ambient = sky_ambient_;
  return v;
}

void PathStreakBuild::FillPods(const ParticleStreaks& streaks, const int32_t* order) {
  const int n = streaks.size();
  const std::vector<Eigen::Vector4f>& ends = streaks.ends();
  pods_.resize(n);
  for (int k = 0; k < n; ++k) {
    const int i = order != nullptr ? order[k] : k;
    StreakPod& p = pods_[k];
    for (int c = 0; c < 3; ++c) p.a[c] = ends[2 * i][c], p.b[c] = ends[2 * i + 1][c];
    p.r = ends[2 * i].w();
    p.alpha = streaks.alpha()[i];
    p.prim = i;
    p.set = streaks.set_of()[i];
  }
  const int num_sets = static_cast<int>(streaks.frame()->particles.size());
  for (int s = 0; s < num_sets; ++s) sets_.push_back(streaks.SetPod(s));
}

PathStreaks PathStreakBuild::View() const {
  PathStreaks v;
  if (pods_.empty()) return v;
  v.num = static_cast<int32_t>(pods_.size());
  v.nodes = nodes_.data();
  v.root = root_;
  v.streaks = pods_.data();
  v.sets = sets_.data();
  v.num_sets = static_cast<int32_t>(sets_.size());
  v.rain = rain_.empty() ? nullptr : rain_.data();
  v.num_rain = static_cast<int32_t>(rain_.size());
  v.sky_ambient = sky_ambient_;
  return v;
}

}  // namespace penumbra::cuda
