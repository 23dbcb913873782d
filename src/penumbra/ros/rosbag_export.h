#pragma once
// `penumbra export RUN --format rosbag --out FILE.bag` and `--format rosbag2 --out DIR`: a run's
// output folder (README "Outputs") as a ROS 1 bag, written with the rosbag C++ API
// (ros/rosbag_writer.h), or as a ROS 2 bag (rosbag2 folder with one MCAP file,
// ros/rosbag2_writer.h), with the topics and frames the live bridge publishes (ros/ros_graph.h,
// docs/ros.md). both bags hold the same messages with the same stamps and record times:
//
//   cameras  <camera>/frames.csv + rgb/depth PNGs -> image_raw, camera_info, depth/image_raw,
//            depth/camera_info, stamped with the frame's sim time
//   LiDARs   lidar/<name>/index.csv + scan PCDs   -> points (PointCloud2), stamped with the
//            capture time, recorded at the delivery time (capture + latency)
//   IMUs     imu/<name>.csv                       -> data (Imu), likewise
//   robots   trajectory.csv (qpos of every physics step) posed through the composed model
//            (composed.xml) at ros.state_rate_hz: odom (Odometry), joint_states, /tf
//            (odom -> base_link, moving sensors); /tf_static once (map -> odom, sensors fixed
//            to their parent). trajectory.csv holds no velocities: the twist and the joint
//            velocities are backward differences over one physics step; effort is left empty.
//
// names (topics, frames, `ros:` overrides) come from the run's world file (run.json
// "world_file"), which must still be readable. a sample at sim time t has header stamp t and is
// recorded at t (or its delivery time); rosbag's smallest record time is 1 ns, so records of a
// ROS 1 bag at t = 0 are stored at 1 ns (their header stamps stay 0; a ROS 2 bag stores 0). no
// /clock is written: `rosbag play --clock` and `ros2 bag play --clock` publish one.
//
// the run folder's files are read as dataset/run_file.h says (no symbolic link below the run
// folder is followed; images are decoded and checked against camera_info.json,
// dataset/image_convert.h). the bag (file or folder) is written under a temporary name beside
// it, "<bag>.export-tmp-<pid>-<random>", and renamed to its name (never replacing anything) only
// when it is complete; an export that fails (a full disk: exit 1 with the system's reason) or is
// stopped removes it.

#include <atomic>
#include <cstdint>
#include <filesystem>
#include <map>
#include <string>

namespace penumbra {

/// what an export wrote.
struct RosbagExportSummary {
  std::string world_file;                 ///< the world file the names came from
  std::map<std::string, int64_t> counts;  ///< messages per topic
  int64_t messages = 0;                   ///< all messages
};

/// writes the bag `bag_path` (must not exist; its folder is created) from the run folder
/// `run_dir`. if the export fails or is stopped nothing is left at or beside bag_path.
/// @throws ConfigError for a missing or malformed run folder file (naming file and line), a
///         symbolic link or a bad image in it, an unreadable world file, a bag path that exists
///         or does not end in ".bag" (key "--out"); Error if ROS 1 is not in this build or the
///         bag cannot be written (the system's reason, e.g. "No space left on device");
///         ExportStopped (dataset/export_stop.h) when `stop_request` (may be null) reads
///         non-zero, checked between messages.
RosbagExportSummary ExportRosbag(const std::filesystem::path& run_dir,
                                 const std::filesystem::path& bag_path,
                                 const std::atomic<int>* stop_request = nullptr);

/// writes the ROS 2 bag folder `bag_dir` (must not exist; its parent is created):
/// `bag_dir`/metadata.yaml and `bag_dir`/<name>_0.mcap, <name> the folder's name, from the run
/// folder `run_dir`, with the messages ExportRosbag writes. if the export fails or is stopped
/// nothing is left at or beside bag_dir.
/// @throws as ExportRosbag (a `bag_dir` that exists: ConfigError, key "--out"); Error if this
///         build has no ROS 2 (before anything is read).
RosbagExportSummary ExportRosbag2(const std::filesystem::path& run_dir,
                                  const std::filesystem::path& bag_dir,
                                  const std::atomic<int>* stop_request = nullptr);

}  // namespace penumbra
