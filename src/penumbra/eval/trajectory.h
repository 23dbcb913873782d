#pragma once
// timed pose sequences as the TUM RGB-D benchmark's tools read and write them (Sturm et al.,
// "A Benchmark for the Evaluation of RGB-D SLAM Systems", IROS 2012; file format at
// cvg.cit.tum.de/data/datasets/rgbd-dataset/file_formats): one pose per line,
//
//   timestamp tx ty tz qx qy qz qw
//
// time in seconds, translation in metres, the orientation as a unit quaternion (x, y, z, w:
// the scalar LAST). each line is the pose X_WB of the tracked body B in the file's own world
// frame W. fields are separated by spaces, tabs or commas (as TUM's associate.py accepts);
// lines whose first non-blank character is '#' and blank lines are skipped.

#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "penumbra/core/pose.h"

namespace penumbra {

/// a trajectory: poses X_WB at strictly increasing times. `time_sec` and `X_WB` have the
/// same length.
struct Trajectory {
  std::vector<double> time_sec;  ///< s, strictly increasing
  std::vector<Pose> X_WB;        ///< body in the trajectory's world frame; rotations orthonormal

  size_t size() const { return time_sec.size(); }
  bool empty() const { return time_sec.empty(); }
  /// the positions p_WB (m), one column per pose.
  Eigen::Matrix3Xd Positions() const;
};

/// most a quaternion's norm may differ from 1 in a TUM file; it is normalised on reading.
/// (a file written with 4 decimals is off by < 1e-3; a norm far from 1 means wrong columns.)
constexpr double kTumQuaternionNormTolerance = 1e-2;

/// input limits of TUM files (docs/evaluation.md "Input limits"): most bytes of a file
/// (256 MiB, about 3 million poses) and of one line (4096).
constexpr uint64_t kTumMaxFileBytes = uint64_t{256} << 20;
constexpr size_t kTumMaxLineBytes = 4096;
/// most |tx|, |ty|, |tz| (m): 1000 km, beyond any trajectory a robot drives, and small enough
/// that squared errors and sums of them stay exact enough in doubles.
constexpr double kTumMaxAbsCoordinateM = 1e6;
/// most |timestamp| (s): 1e10 s is the year 2286 as Unix time.
constexpr double kTumMaxAbsTimestampSec = 1e10;

/// parses TUM trajectory text. `source` names the text in errors (a file path).
/// each pose line must hold exactly 8 finite decimal numbers; quaternions are normalised.
/// @throws ConfigError(source, line, "", problem) naming the 1-based line and what was
///         expected, for: a line longer than kTumMaxLineBytes, a NUL or other control byte
///         (binary data, not text), a line with another number of fields, a field that is not
///         a finite number, a position coordinate beyond kTumMaxAbsCoordinateM or a timestamp
///         beyond kTumMaxAbsTimestampSec, a quaternion whose norm is 0 or differs from 1 by
///         more than kTumQuaternionNormTolerance, a timestamp not after the previous pose's;
///         and (line 0) for text that holds no pose at all or is larger than kTumMaxFileBytes.
Trajectory ParseTumTrajectory(std::string_view text, const std::string& source);

/// reads and parses a TUM trajectory file (ParseTumTrajectory). the file is read in blocks
/// and refused at the first NUL or control byte, overlong line or byte past kTumMaxFileBytes,
/// so that /dev/zero or a huge binary file stops at once.
/// @throws ConfigError naming `path` (and the line) if it cannot be read or does not parse.
Trajectory ReadTumTrajectory(const std::filesystem::path& path);

/// the trajectory as TUM text: a '#' header line, then one line per pose, every number in the
/// shortest form that reads back to the same double, quaternion with the scalar last.
/// ParseTumTrajectory reads positions and times back exactly (quaternions up to the
/// normalisation's rounding).
std::string FormatTumTrajectory(const Trajectory& trajectory);

}  // namespace penumbra
