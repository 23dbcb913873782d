#pragma once
// MJCF frame orientation, resolved exactly as MuJoCo 2.2.2 does it
// (mjCAlternative::Set in src/user/user_objects.cc): start from quat, then
// axisangle, xyaxes, zaxis, euler each override in that order when given; angles
// follow compiler angle, euler axes follow compiler eulerseq (lowercase letters:
// rotating axes, post-multiplied; uppercase: fixed axes, pre-multiplied).
// quaternions are (w, x, y, z). internal to src/penumbra/compose.

#include <Eigen/Geometry>
#include <optional>
#include <string>
#include <vector>

namespace penumbra::compose {

/// the orientation attributes of one element (each already merged with its defaults).
struct OrientationSpec {
  std::optional<std::vector<double>> quat;       ///< 4 values
  std::optional<std::vector<double>> axisangle;  ///< 4 values: axis, angle
  std::optional<std::vector<double>> xyaxes;     ///< 6 values
  std::optional<std::vector<double>> zaxis;      ///< 3 values
  std::optional<std::vector<double>> euler;      ///< 3 values
  bool Any() const { return quat || axisangle || xyaxes || zaxis || euler; }
  bool AnyAlternative() const { return axisangle || xyaxes || zaxis || euler; }
};

/// the unit quaternion MuJoCo compiles `spec` into.
/// @param degree   compiler angle="degree"
/// @param eulerseq compiler eulerseq, 3 letters of xyzXYZ
/// @return nullopt and `error` set for degenerate input (zero axis, wrong value counts)
std::optional<Eigen::Quaterniond> ResolveOrientation(const OrientationSpec& spec, bool degree,
                                                     const std::string& eulerseq,
                                                     std::string* error);

/// MuJoCo's mjuu_z2quat: the minimal rotation taking +z to `z` (any length > 0).
Eigen::Quaterniond QuatFromZAxis(const Eigen::Vector3d& z);

/// quaternion as 4 numbers (w, x, y, z).
std::vector<double> QuatToVector(const Eigen::Quaterniond& q);

}  // namespace penumbra::compose
