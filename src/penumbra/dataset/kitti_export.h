#pragma once
// KITTI odometry layout (Geiger et al., CVPR 2012; the odometry development kit's readme) of a
// run's camera (and optional second camera of a stereo pair):
//
//   OUT/sequences/<seq>/image_0/NNNNNN.png  8-bit greyscale images of camera 0 (image_convert.h)
//   OUT/sequences/<seq>/image_1/NNNNNN.png  the same of camera 1 (with a second camera)
//   OUT/sequences/<seq>/image_2|3/NNNNNN.png the colour images of cameras 0 | 1, byte for byte
//   OUT/sequences/<seq>/times.txt           one line per frame: time in seconds ("%e")
//   OUT/sequences/<seq>/calib.txt           "P0: " .. "P3: " 12 numbers (3x4 row-major) and
//                                           "Tr: " 12 numbers
//   OUT/poses/<seq>.txt                     one line per frame: 12 numbers, the 3x4 row-major
//                                           pose of camera 0 at frame i in the frame of camera
//                                           0 at frame 0 (T_0i, takes points of frame i to
//                                           frame 0)
//
// NNNNNN counts frames from 000000 (the run's frame indices are renumbered). camera frames are
// OpenCV optical frames (x right, y down, z forward) as KITTI's. P0 = K0 [I | 0];
// P1 = K1 [R_10 | t_10] with X_10 camera 0 in camera 1 (for Penumbra's parallel stereo pairs
// R = I and t = (-baseline, 0, 0), KITTI's rectified form); P2 = P0 and P3 = P1 (images 2 and 3
// are the colour images of the same cameras); without a second camera P1 = P0 and P3 = P2.
// Tr (Velodyne to camera 0) is the identity: no LiDAR scans are exported. times: sim time.
// KITTI's images are undistorted and rectified, so a camera with lens distortion is refused.

#include <atomic>
#include <cstdint>
#include <filesystem>
#include <string>

#include "penumbra/dataset/run_folder.h"

namespace penumbra {

/// X_10: the optical frame of `cam0` in that of `cam1`, equal at every frame.
/// @throws ConfigError if the cameras' frames differ in count or time (KITTI's pairs are
///         synchronised), or the relative pose changes between frames by more than 1e-6 m or
///         1e-6 rad (not a rigid pair).
Pose StereoExtrinsics(const RunCamera& cam0, const RunCamera& cam1);

/// the calib.txt text for camera 0, optional camera 1 with its X_10.
std::string KittiCalib(const RunCamera& cam0, const RunCamera* cam1, const Pose& X_10);

/// writes the sequence `sequence` of camera 0 (and camera 1 when not null) under `out` (an
/// existing, empty folder). returns the number of frames.
/// @throws ConfigError as StereoExtrinsics, for a camera with distortion, no rgb images or a
///         missing image or one that fails the checks of dataset/image_convert.h; Error if a
///         file cannot be written; ExportStopped when `stop_request` (may be null) reads non-zero
///         between frames.
int64_t ExportKitti(const RunCamera& cam0, const RunCamera* cam1, const std::string& sequence,
                    const std::filesystem::path& out,
                    const std::atomic<int>* stop_request = nullptr);

}  // namespace penumbra
