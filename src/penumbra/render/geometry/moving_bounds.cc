#include "penumbra/render/geometry/moving_bounds.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace penumbra {
int MovingBounds::AddBody(const std::vector<Box>& boxes_B, int cluster) {
  Body body;
  body.cluster = cluster;
  Eigen::Vector3f lo = Eigen::Vector3f::Constant(std::numeric_limits<float>::infinity());
  Eigen::Vector3f hi = -lo;
  for (const Box& b : boxes_B) {
    PaddedBox pb{b, 0};
    const float half_diagonal = b.axes.colwise().norm().norm();
    pb.pad = kMarginM + kMarginRel * (half_diagonal + b.c.cwiseAbs().maxCoeff());
    body.boxes_B.push_back(pb);
    // axis-aligned extent of the box: |axes| summed along each row.
    const Eigen::Vector3f e = b.axes.cwiseAbs().rowwise().sum();
    lo = lo.cwiseMin(b.c - e);
    hi = hi.cwiseMax(b.c + e);
  }
  if (!body.boxes_B.empty()) {
    body.sphere_c_B = 0.5f * (lo + hi);
    body.sphere_r = 0;
    for (const PaddedBox& pb : body.boxes_B)
      body.sphere_r = std::max(body.sphere_r, (pb.box.c - body.sphere_c_B).norm() +
                                                  pb.box.axes.colwise().norm().norm() + pb.pad);
    // rounding of the sum above.
    body.sphere_r += kMarginM + kMarginRel * body.sphere_r;
  }
  const int index = static_cast<int>(bodies_.size());
  bodies_.push_back(std::move(body));
  boxes_W_.insert(boxes_W_.end(), bodies_.back().boxes_B.begin(), bodies_.back().boxes_B.end());
  box_begin_.push_back(static_cast<int>(boxes_W_.size()));
  sphere_c_W_.push_back(bodies_.back().sphere_c_B);
  sphere_r_W_.push_back(bodies_.back().sphere_r);
  if (!bodies_.back().boxes_B.empty()) {
    auto it = std::find_if(clusters_.begin(), clusters_.end(),
                           [&](const Cluster& c) { return c.id == cluster; });
    if (it == clusters_.end()) {
      clusters_.push_back(Cluster{cluster, {}, {0, 0, 0}, -1});
      it = clusters_.end() - 1;
    }
    it->bodies.push_back(index);
  }
  SetPose(index, Pose::Identity());
  CommitPoses();
  return index;
}

void MovingBounds::CommitPoses() {
  for (Cluster& cl : clusters_) {
    Eigen::Vector3f lo = Eigen::Vector3f::Constant(std::numeric_limits<float>::infinity());
    Eigen::Vector3f hi = -lo;
    for (int b : cl.bodies) {
      lo = lo.cwiseMin(sphere_c_W_[b] - Eigen::Vector3f::Constant(sphere_r_W_[b]));
      hi = hi.cwiseMax(sphere_c_W_[b] + Eigen::Vector3f::Constant(sphere_r_W_[b]));
    }
    cl.c = 0.5f * (lo + hi);
    cl.r = 0;
    for (int b : cl.bodies) cl.r = std::max(cl.r, (sphere_c_W_[b] - cl.c).norm() + sphere_r_W_[b]);
    cl.r += kMarginM + kMarginRel * (cl.r + cl.c.cwiseAbs().maxCoeff());
  }
}

void MovingBounds::SetPose(int body, const Pose& X_WB) {
  const Body& b = bodies_[body];
  const Eigen::Matrix3f R = X_WB.linear().cast<float>();
  const Eigen::Vector3f p = X_WB.translation().cast<float>();
  for (size_t i = 0; i < b.boxes_B.size(); ++i) {
    const PaddedBox& src = b.boxes_B[i];
    PaddedBox& dst = boxes_W_[box_begin_[body] + i];
    dst.box.c = R * src.box.c + p;
    dst.box.axes = R * src.box.axes;
    dst.pad = src.pad + kMarginRel * dst.box.c.cwiseAbs().maxCoeff();
  }
  sphere_c_W_[body] = R * b.sphere_c_B + p;
  if (b.sphere_r >= 0)
    sphere_r_W_[body] = b.sphere_r + kMarginRel * sphere_c_W_[body].cwiseAbs().maxCoeff();
}

bool MovingBounds::MayHit(const RayCone& cone) const {
  if (std::none_of(sphere_r_W_.begin(), sphere_r_W_.end(), [](float r) { return r >= 0; }))
    return false;
  if (!cone.valid) return true;
  const Eigen::Vector3f& o = cone.apex;
  // a ball (c, radius) or box lies outside a plane if it is beyond it by more than delta and
  // the rounding of the signed distance and of the cone's planes (relative to |c - o|).
  auto outside = [&](const Eigen::Vector3f& v, float radius, float slack) {
    for (const RayCone::Plane& pl : cone.planes)
      if (pl.n.dot(v) - pl.offset + radius + slack < 0) return true;
    return false;
  };
  for (int b = 0; b < num_bodies(); ++b) {
    if (sphere_r_W_[b] < 0) continue;
    const Eigen::Vector3f vs = sphere_c_W_[b] - o;
    if (outside(vs, sphere_r_W_[b], cone.delta + kMarginRel * vs.cwiseAbs().maxCoeff())) continue;
    for (int i = box_begin_[b]; i < box_begin_[b + 1]; ++i) {
      const PaddedBox& pb = boxes_W_[i];
      const Eigen::Vector3f v = pb.box.c - o;
      const float slack = cone.delta + kMarginRel * v.cwiseAbs().maxCoeff() + pb.pad;
      auto separates = [&](const Eigen::Vector3f& n, float offset) {
        const float radius = (n.transpose() * pb.box.axes).cwiseAbs().sum();
        return n.dot(v) - offset + radius + slack < 0;
      };
      bool separated = false;
      for (const RayCone::Plane& pl : cone.planes)
        if (separates(pl.n, pl.offset)) {
          separated = true;
          break;
        }
      // the box's face normals +-e through the apex, where every direction makes an angle of
      // at most 90 deg with e (e . axis >= sin theta): a camera's own housing right behind it.
      for (int j = 0; j < 3 && !separated; ++j) {
        const float len = pb.box.axes.col(j).norm();
        if (!(len > 0)) continue;
        const Eigen::Vector3f e = pb.box.axes.col(j) / len;
        const float e_a = e.dot(cone.axis);
        if (e_a >= cone.sin_theta)
          separated = separates(e, 0);
        else if (-e_a >= cone.sin_theta)
          separated = separates(-e, 0);
      }
      if (!separated) return true;
    }
  }
  return false;
}

LaneMask MovingBounds::SegmentsMayHit(const Vec3Lanes& o, const Vec3Lanes& d, const Lanes& tmax,
                                      const LaneMask& active) const {
  LaneMask may;
  if (clusters_.empty() || !active.any()) return may;
  const Lanes inv_dd = 1.0f / d.Dot(d);
  // the lanes of `in` whose segment passes within the sphere (c, r).
  auto within = [&](const Eigen::Vector3f& c, float r, LaneMask in) {
    const Lanes wx = c.x() - o.x, wy = c.y() - o.y, wz = c.z() - o.z;
    // the segment's point closest to the centre, its parameter clamped to [0, tmax].
    const Lanes t = ((wx * d.x + wy * d.y + wz * d.z) * inv_dd).max(0.0f).min(tmax);
    const Lanes ex = wx - t * d.x, ey = wy - t * d.y, ez = wz - t * d.z;
    const Lanes dist2 = ex * ex + ey * ey + ez * ez;
    // the radius grown by the rounding of e, relative to |w|; a NaN lane counts as within.
    const Lanes rr = r + kMarginRel * wx.abs().max(wy.abs()).max(wz.abs());
    return in && !GreaterThan(dist2, rr * rr);
  };
  for (const Cluster& cl : clusters_) {
    const LaneMask near_cluster = within(cl.c, cl.r, active && !may);
    if (!near_cluster.any()) continue;
    for (int b : cl.bodies) may = may || within(sphere_c_W_[b], sphere_r_W_[b], near_cluster);
  }
  return may;
}

}  // namespace penumbra
