#pragma once
// reference motion along a polyline for multirotor position control: straight segments
// flown one after the other, each rest to rest with a trapezoidal speed profile whose
// ramps are harmonic (cosine) so the acceleration is continuous and the attitude loop can
// follow it: over a ramp of T_a = pi v / (2 a), speed(x) = v (1 - cos(pi x / T_a)) / 2,
// acceleration peaks at a; then cruise at v and the mirrored ramp down to a stop at the
// segment's end (peak speed sqrt(2 a L / pi) when the segment is shorter than pi v^2 / (2 a)).
// stopping at every corner keeps the reference on the straight lines, so a controller
// tracking position, velocity and acceleration of the reference (feed-forward) stays close
// to the path (L. Biagiotti and C. Melchiorri, "Trajectory Planning for Automatic Machines
// and Robots", Springer 2008: the trapezoidal velocity profile, with harmonic trajectories
// as its ramps).
//
// the path has its own clock: the controller advances it by dt each update, or by less
// when the vehicle lags far behind (see MultirotorPid), so the reference waits for it.

#include <Eigen/Core>
#include <vector>

namespace penumbra {

/// a sampled point of the reference.
struct PathSample {
  Eigen::Vector3d position = Eigen::Vector3d::Zero();      ///< m, world
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();      ///< m/s, world
  Eigen::Vector3d acceleration = Eigen::Vector3d::Zero();  ///< m/s^2, world
  Eigen::Vector3d jerk = Eigen::Vector3d::Zero();          ///< m/s^3, world
  int segment = 0;  ///< index of the segment the sample lies on (0 = start -> points[0])
};

/// rest-to-rest trapezoidal motion through a list of points (see the file comment).
class MultirotorPath {
 public:
  MultirotorPath() = default;
  /// path from `start` through `points` (world, m) at cruise speed `speed_m_s` (> 0) with
  /// peak acceleration `accel_m_s2` (> 0). zero-length segments take no time.
  /// @throws Error if speed or acceleration are not finite and > 0.
  MultirotorPath(const Eigen::Vector3d& start, std::vector<Eigen::Vector3d> points,
                 double speed_m_s, double accel_m_s2);

  /// the reference `t_sec` after the start (clamped to [0, duration]); at and after the end
  /// it rests at the last point.
  PathSample Sample(double t_sec) const;
  /// total time from the start to the rest at the last point (s).
  double duration_sec() const { return end_time_.empty() ? 0 : end_time_.back(); }
  /// the polyline: start, then the points.
  const std::vector<Eigen::Vector3d>& vertices() const { return vertices_; }

 private:
  std::vector<Eigen::Vector3d> vertices_;
  std::vector<double> length_, end_time_, t_accel_, v_peak_;
};

}  // namespace penumbra
