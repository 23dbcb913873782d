#include "penumbra/ros/rosbag_export.h"

#include <fcntl.h>
#include <fmt/format.h>
#include <spdlog/spdlog.h>
#include <stdio.h>
#include <sys/stat.h>
#include <unistd.h>

#include <Eigen/Geometry>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>

#include "penumbra/core/error.h"
#include "penumbra/core/image.h"
#include "penumbra/dataset/dataset_export.h"
#include "penumbra/dataset/export_stop.h"
#include "penumbra/dataset/image_convert.h"
#include "penumbra/dataset/run_file.h"
#include "penumbra/dataset/run_folder.h"
#include "penumbra/output/pcd_writer.h"
#include "penumbra/physics/simulation.h"
#include "penumbra/ros/ros_convert.h"
#include "penumbra/ros/ros_graph.h"
#include "penumbra/ros/rosbag2_writer.h"
#include "penumbra/ros/rosbag_writer.h"
#include "penumbra/scene/sim_time.h"
#include "penumbra/world/ros_config.h"
#include "penumbra/world/world_config.h"

namespace penumbra {

namespace {

namespace fs = std::filesystem;

// the lines of a CSV file after its header, split at commas, with their 1-based line numbers
struct CsvRows {
  fs::path path;
  std::vector<std::string> header;
  std::vector<std::vector<std::string>> rows;
  std::vector<int> lines;

  double Number(size_t row, size_t col) const {
    if (col >= rows[row].size())
      throw ConfigError(path.string(), lines[row], header.size() > col ? header[col] : "",
                        "missing column " + std::to_string(col + 1));
    const std::string& s = rows[row][col];
    char* end = nullptr;
    const double v = std::strtod(s.c_str(), &end);
    if (s.empty() || end != s.c_str() + s.size())
      throw ConfigError(path.string(), lines[row], header.size() > col ? header[col] : "",
                        "'" + s + "' is not a number");
    return v;
  }
};

std::vector<std::string> SplitComma(const std::string& line) {
  std::vector<std::string> out;
  std::stringstream ss(line);
  std::string cell;
  while (std::getline(ss, cell, ',')) out.push_back(cell);
  if (!line.empty() && line.back() == ',') out.emplace_back();
  return out;
}

// `relative` under the run folder `run_dir` (read as dataset/run_file.h says)
CsvRows ReadCsvRows(const fs::path& run_dir, const fs::path& relative,
                    const std::string& first_columns) {
  const fs::path path = run_dir / relative;
  std::istringstream in(ReadRunFile(run_dir, relative));
  CsvRows csv;
  csv.path = path;
  std::string line;
  if (!std::getline(in, line) || line.rfind(first_columns, 0) != 0)
    throw ConfigError(path.string(), 1, "", "header does not start with '" + first_columns + "'");
  csv.header = SplitComma(line);
  int n = 1;
  while (std::getline(in, line)) {
    ++n;
    if (line.empty()) continue;
    csv.rows.push_back(SplitComma(line));
    csv.lines.push_back(n);
  }
  return csv;
}

nlohmann::json ReadJsonFile(const fs::path& run_dir, const fs::path& relative) {
  const fs::path path = run_dir / relative;
  const std::string text = ReadRunFile(run_dir, relative);
  try {
    return nlohmann::json::parse(text);
  } catch (const nlohmann::json::exception& e) {
    throw ConfigError(path.string(), 0, "", std::string("not valid JSON: ") + e.what());
  }
}

// the run's world (names and `ros:` overrides): run.json "world_file"
WorldConfig RunWorld(const fs::path& run_dir, std::string* world_file) {
  const fs::path manifest = run_dir / "run.json";
  const nlohmann::json j = ReadJsonFile(run_dir, "run.json");
  if (!j.contains("world_file") || !j["world_file"].is_string())
    throw ConfigError(manifest.string(), 0, "world_file",
                      "missing; expected the world file of the run");
  *world_file = j["world_file"].get<std::string>();
  // run.json may come from someone else: only a world file is read (by its ending, a regular
  // file, not through a link at its name), and no error quotes its content
  const std::string shown = SanitizeForMessage(*world_file, 300);
  auto refuse = [&](const std::string& why) {
    return ConfigError(manifest.string(), 0, "world_file",
                       "the run's world file '" + shown + "' " + why +
                           "; the export names topics and "
                           "frames from it");
  };
  const std::string ext = fs::path(*world_file).extension().string();
  if (ext != ".yaml" && ext != ".yml" && ext != ".xml" && ext != ".urdf")
    throw refuse("is not a world file (.yaml, .yml, .xml or .urdf) and is not read");
  struct stat st {};
  if (::lstat(world_file->c_str(), &st) != 0) throw refuse("is gone");
  if (S_ISLNK(st.st_mode)) throw refuse("is a symbolic link (not followed)");
  if (!S_ISREG(st.st_mode)) throw refuse("is not a regular file");
  if (ext == ".xml" || ext == ".urdf") return WorldForBareModel(*world_file);
  try {
    return LoadWorldFile(*world_file);
  } catch (const Error& e) {
    const auto* c = dynamic_cast<const ConfigError*>(&e);
    throw refuse(std::string("does not load as a world") +
                 (c && c->line() > 0 ? " (line " + std::to_string(c->line()) + ")" : "") +
                 " (its error is not shown: run.json may come from someone else; run `penumbra "
                 "run` on it to see why)");
  }
}

// gives the complete bag `from` its name `to`, never replacing a file there
void RenameNoReplace(const fs::path& from, const fs::path& to) {
  auto exists = [&] {
    return ConfigError("", 0, "--out",
                       "'" + to.string() +
                           "' was created during the export; expected a new file (never "
                           "overwritten)");
  };
  if (::renameat2(AT_FDCWD, from.c_str(), AT_FDCWD, to.c_str(), RENAME_NOREPLACE) == 0) return;
  if (errno == EEXIST) throw exists();
  if (errno != EINVAL && errno != ENOSYS)
    throw Error("cannot rename " + from.string() + " to " + to.string() + ": " +
                std::strerror(errno));
  // a file system without RENAME_NOREPLACE: a hard link fails on an existing name too
  if (::link(from.c_str(), to.c_str()) != 0) {
    if (errno == EEXIST) throw exists();
    throw Error("cannot link " + from.string() + " to " + to.string() + ": " +
                std::strerror(errno));
  }
  ::unlink(from.c_str());
}

// gives the complete bag folder `from` its name `to`, never replacing anything there
void RenameFolderNoReplace(const fs::path& from, const fs::path& to) {
  auto exists = [&] {
    return ConfigError("", 0, "--out",
                       "'" + to.string() +
                           "' was created during the export; expected a new folder (never "
                           "overwritten)");
  };
  if (::renameat2(AT_FDCWD, from.c_str(), AT_FDCWD, to.c_str(), RENAME_NOREPLACE) == 0) return;
  if (errno == EEXIST || errno == ENOTEMPTY) throw exists();
  if (errno != EINVAL && errno != ENOSYS)
    throw Error("cannot rename " + from.string() + " to " + to.string() + ": " +
                std::strerror(errno));
  // a file system without RENAME_NOREPLACE: rename(2) would replace an empty folder there
  std::error_code ec;
  if (fs::exists(fs::symlink_status(to, ec))) throw exists();
  if (::rename(from.c_str(), to.c_str()) != 0)
    throw Error("cannot rename " + from.string() + " to " + to.string() + ": " +
                std::strerror(errno));
}

// the ROS 1 bag being written: "<bag>.export-tmp-<pid>-<random>" beside it (O_EXCL |
// O_NOFOLLOW), locked while this export works, removed unless the export completes
struct Ros1Target {
  fs::path final_path;
  UniqueFd lock;
  fs::path temp;
  bool done = false;
  std::unique_ptr<RosbagWriter> bag;

  explicit Ros1Target(const fs::path& path) : final_path(path) {
    temp = MakeSiblingTempFile(path, ".export-tmp", &lock);
    try {
      bag = std::make_unique<RosbagWriter>(temp.string(), path.string());
    } catch (...) {
      Remove();
      throw;
    }
  }
  ~Ros1Target() {
    bag.reset();
    if (!done) Remove();
  }
  void Remove() {
    std::error_code e;
    fs::remove(temp, e);
  }
  void Finish() {
    bag->Close();
    RenameNoReplace(temp, final_path);
    done = true;
  }
};

// the ROS 2 bag being written: the folder "<dir>.export-tmp-<pid>-<random>" beside it (mkdir),
// locked while this export works, removed with its files unless the export completes
struct Ros2Target {
  fs::path final_path;
  UniqueFd lock;
  fs::path temp;
  bool done = false;
  std::unique_ptr<Rosbag2Writer> bag;

  explicit Ros2Target(const fs::path& path) : final_path(path) {
    temp = MakeSiblingTempFolder(path, ".export-tmp", &lock);
    try {
      bag = std::make_unique<Rosbag2Writer>(temp, path.filename().string(), path.string());
    } catch (...) {
      Remove();
      throw;
    }
  }
  ~Ros2Target() {
    bag.reset();
    if (!done) Remove();
  }
  void Remove() {
    std::error_code e;
    fs::remove_all(temp, e);
  }
  void Finish() {
    bag->Close();
    RenameFolderNoReplace(temp, final_path);
    done = true;
  }
};

// the bag folder named by --out `out` ("DIR/" is "DIR")
fs::path Rosbag2Folder(const fs::path& out) {
  fs::path p = out.lexically_normal();
  if (p.filename().empty()) p = p.parent_path();
  const std::string name = p.filename().string();
  if (p.empty() || name == "." || name == "..")
    throw ConfigError("", 0, "--out",
                      "'" + out.string() + "'; expected the path of a new ROS 2 bag folder");
  return p;
}

// writes the run's messages (the header comment) into a bag made by Target(bag_path) (above),
// finished and renamed to bag_path when complete
template <typename Target>
RosbagExportSummary ExportRun(const fs::path& run_dir, const fs::path& bag_path,
                              const std::atomic<int>* stop_request);

}  // namespace

RosbagExportSummary ExportRosbag(const fs::path& run_dir, const fs::path& bag_path,
                                 const std::atomic<int>* stop_request) {
  if (bag_path.extension() != ".bag")
    throw ConfigError("", 0, "--out",
                      "'" + bag_path.string() + "'; expected a bag file name ending in .bag");
  std::error_code ec;
  if (fs::exists(fs::symlink_status(bag_path, ec)))
    throw ConfigError(
        "", 0, "--out",
        "'" + bag_path.string() + "' exists; expected a new file (never overwritten)");
  return ExportRun<Ros1Target>(run_dir, bag_path, stop_request);
}

RosbagExportSummary ExportRosbag2(const fs::path& run_dir, const fs::path& bag_dir,
                                  const std::atomic<int>* stop_request) {
  RequireRosbag2();
  const fs::path dir = Rosbag2Folder(bag_dir);
  std::error_code ec;
  if (fs::exists(fs::symlink_status(dir, ec)))
    throw ConfigError("", 0, "--out",
                      "'" + bag_dir.string() +
                          "' exists; expected a new folder for the ROS 2 bag (never overwritten)");
  return ExportRun<Ros2Target>(run_dir, dir, stop_request);
}

namespace {

template <typename Target>
RosbagExportSummary ExportRun(const fs::path& run_dir, const fs::path& bag_path,
                              const std::atomic<int>* stop_request) {
  std::error_code ec;
  const RunFolder run(run_dir);
  RosbagExportSummary summary;
  const WorldConfig world = RunWorld(run_dir, &summary.world_file);

  // the composed model poses the robots from trajectory.csv
  const fs::path composed = run_dir / "composed.xml";
  if (StatRunEntry(run_dir, "composed.xml") != RunEntry::kFile)
    throw ConfigError(composed.string(), 0, "", "missing; expected the run's composed model");
  Simulation sim = Simulation::LoadFromFile(composed.string());
  const ModelInfo& model = sim.model_info();

  // mounts: cameras as the run wrote them (camera_info.json, rig.json), LiDARs and IMUs from the
  // world file
  std::vector<RosSensorMount> mounts;
  std::vector<RunCamera> cameras;
  for (const std::string& name : run.CameraNames()) {
    RunCamera cam = run.ReadCamera(name);
    RosSensorMount m;
    m.name = name;
    m.kind = RosSensorKind::kCamera;
    m.intrinsics.width = cam.width;
    m.intrinsics.height = cam.height;
    m.intrinsics.fx = cam.fx;
    m.intrinsics.fy = cam.fy;
    m.intrinsics.cx = cam.cx;
    m.intrinsics.cy = cam.cy;
    m.intrinsics.k1 = cam.distortion[0];
    m.intrinsics.k2 = cam.distortion[1];
    m.intrinsics.p1 = cam.distortion[2];
    m.intrinsics.p2 = cam.distortion[3];
    m.intrinsics.k3 = cam.distortion[4];
    m.rgb = cam.has_rgb;
    m.depth = cam.has_depth;
    if (const std::optional<RunMount> mount = run.CameraMount(name)) {
      m.body = mount->body == "world" ? 0 : model.Find(ModelObject::kBody, mount->body);
      if (m.body < 0)
        throw ConfigError((run_dir / "rig.json").string(), 0, "cameras." + name + ".body",
                          "body '" + mount->body + "' is not in composed.xml");
      m.X_BS = mount->X_BS;
    } else {
      // an MJCF camera: posed by the model's own camera
      m.body = -1;
      for (const CameraSpec& c : sim.scene().cameras)
        if (c.name == name) m.mjcf_camera = c.mjcf_camera;
      if (m.mjcf_camera < 0)
        throw ConfigError((run_dir / "camera_info.json").string(), 0, name,
                          "camera '" + name +
                              "' has no mount in rig.json and is no MJCF camera "
                              "of composed.xml");
    }
    mounts.push_back(m);
    cameras.push_back(std::move(cam));
  }
  SceneDescription no_cameras;  // world cameras came from the run folder above
  for (RosSensorMount& m : SensorMountsOf(world, model, no_cameras)) mounts.push_back(m);
  const RosGraph graph =
      BuildRosGraph(world, LoadRosConfig(world), model, mounts, sim.MocapBodyNames());

  CheckExportStop(stop_request);
  fs::create_directories(fs::absolute(bag_path).parent_path(), ec);
  // what killed exports left beside the bag (their process gone, no lock held on them); the
  // bag is written under "<bag>.export-tmp-<pid>-<random>" (O_EXCL | O_NOFOLLOW), locked while
  // this export works
  for (const fs::path& stale : RemoveStaleExportTemps(bag_path))
    spdlog::info("removed {}, left by an export that was killed", stale.string());
  Target target(bag_path);
  auto& bag = *target.bag;
  auto count = [&](const std::string& topic) { ++summary.counts[topic]; };

  // cameras
  for (size_t ci = 0; ci < cameras.size(); ++ci) {
    const RunCamera& cam = cameras[ci];
    const RosSensorGraph& s = *graph.FindSensor(cam.name);
    for (const RunFrame& f : cam.frames) {
      CheckExportStop(stop_request);
      const RosHeader header = MakeRosHeader(f.time_sec, s.frame_id);
      const int64_t t = header.stamp_ns;
      const RosCameraInfo info = CameraInfoToRos(s.mount.intrinsics, 0, header);
      if (cam.has_rgb) {
        // decoded and checked against camera_info.json (dataset/image_convert.h)
        const RunImage png = ReadRunImage(cam, std::string(Info(ImageKind::kRgb).folder), f.index);
        ImageU8 rgb(png.width, png.height, 3);
        for (size_t i = 0; i < png.samples.size(); ++i)
          rgb.data[i] = static_cast<uint8_t>(png.samples[i]);
        bag.Write(s.image_topic, t, RgbToRos(std::move(rgb), header));
        bag.Write(s.info_topic, t, info);
        count(s.image_topic);
        count(s.info_topic);
      }
      if (cam.has_depth) {
        const RunImage png =
            ReadRunImage(cam, std::string(Info(ImageKind::kDepth).folder), f.index);
        bag.Write(s.depth_image_topic, t, DepthMmToRos(png.width, png.height, png.samples, header));
        bag.Write(s.depth_info_topic, t, info);
        count(s.depth_image_topic);
        count(s.depth_info_topic);
      }
    }
  }

  // LiDARs and IMUs
  for (const SensorConfig& sc : world.sensors) {
    const RosSensorGraph* s = graph.FindSensor(sc.name);
    if (!s) continue;
    const int64_t latency_ns = RosStampNs(sc.latency_sec);
    if (sc.kind() == SensorKind::kLidar) {
      const fs::path rel = fs::path(LidarSensorParams::kOutputFolder) / sc.name;
      if (StatRunEntry(run_dir, rel) != RunEntry::kFolder) continue;
      const fs::path dir = run_dir / rel;
      const CsvRows index =
          ReadCsvRows(run_dir, rel / "index.csv", "scan,capture_time_sec,delivery_time_sec,file");
      for (size_t r = 0; r < index.rows.size(); ++r) {
        CheckExportStop(stop_request);
        const double capture = index.Number(r, 1), delivery = index.Number(r, 2);
        if (index.rows[r].size() < 4)
          throw ConfigError(index.path.string(), index.lines[r], "file",
                            "missing; expected the scan's PCD file name");
        // a scan file named in index.csv: a file of this LiDAR's folder, reached by no link
        const fs::path scan(index.rows[r][3]);
        if (!IsPlainRelativePath(scan) || std::distance(scan.begin(), scan.end()) != 1 ||
            StatRunEntry(run_dir, rel / scan) != RunEntry::kFile)
          throw ConfigError(index.path.string(), index.lines[r], "file",
                            "'" + scan.string() +
                                "' is not a regular file in the LiDAR's folder; expected the "
                                "name of a scan written by `penumbra run`");
        const std::vector<LidarPoint> points = ReadPcd((dir / scan).string());
        bag.Write(s->points_topic, RosStampNs(delivery),
                  PointsToRos(points, MakeRosHeader(capture, s->frame_id)));
        count(s->points_topic);
      }
    } else if (sc.kind() == SensorKind::kImu) {
      if (StatRunEntry(run_dir, fs::path(ImuSensorParams::kOutputFolder) / (sc.name + ".csv")) !=
          RunEntry::kFile)
        continue;
      const RunImu imu = run.ReadImu(sc.name);
      CheckExportStop(stop_request);
      for (const RunImuSample& x : imu.samples) {
        const RosHeader header = MakeRosHeader(x.time_sec, s->frame_id);
        bag.Write(s->imu_topic, header.stamp_ns + latency_ns,
                  ImuToRos(x.accel_m_s2, x.gyro_rad_s, s->mount.accel_noise_density,
                           s->mount.gyro_noise_density, s->mount.rate_hz, header));
        count(s->imu_topic);
      }
    }
  }

  // robots: trajectory.csv rows posed through the composed model at the state rate
  const fs::path trajectory = run_dir / "trajectory.csv";
  if (StatRunEntry(run_dir, "trajectory.csv") == RunEntry::kFile) {
    const CsvRows traj = ReadCsvRows(run_dir, "trajectory.csv", "step,time_sec");
    const size_t nq = static_cast<size_t>(model.nq);
    SimState state = sim.GetState();
    const double dt = sim.timestep();
    auto snapshot_of = [&](size_t row) {
      const int64_t step = std::llround(traj.Number(row, 0));
      state.step = step;
      state.time_sec = SimTimeOfStep(step, dt);
      if (traj.rows[row].size() != 2 + nq)
        throw ConfigError(trajectory.string(), traj.lines[row], "",
                          std::to_string(traj.rows[row].size() - 2) + " qpos values; expected " +
                              std::to_string(nq) + " (the nq of composed.xml)");
      for (size_t i = 0; i < nq; ++i) state.qpos[i] = traj.Number(row, 2 + i);
      sim.SetState(state);
      return sim.Snapshot(Simulation::SnapshotContent::kPoses);
    };
    bool first = true;
    std::optional<WorldSnapshot> previous;
    size_t previous_row = 0;
    int64_t k = 0;
    for (size_t row = 0; row < traj.rows.size(); ++row) {
      CheckExportStop(stop_request);
      const double time = traj.Number(row, 1);
      if (time < static_cast<double>(k) / graph.state_rate_hz) continue;
      while (static_cast<double>(k) / graph.state_rate_hz <= time) ++k;
      const WorldSnapshot snap = snapshot_of(row);
      // the step before, for the backward differences
      std::optional<WorldSnapshot> before;
      if (row > 0) before = row - 1 == previous_row && previous ? *previous : snapshot_of(row - 1);
      const int64_t stamp = RosStampNs(snap.time_sec);
      if (first) {
        for (const RosTransform& tf : StaticTransforms(graph, snap)) {
          bag.Write("/tf_static", stamp, tf);
          count("/tf_static");
        }
        first = false;
      }
      for (const RosTransform& tf : DynamicTransforms(graph, snap)) {
        bag.Write("/tf", stamp, tf);
        count("/tf");
      }
      for (const RosRobotGraph& r : graph.robots) {
        Eigen::Matrix<double, 6, 1> V = Eigen::Matrix<double, 6, 1>::Zero();
        std::vector<double> qvel;
        if (before) {
          const double h = snap.time_sec - before->time_sec;
          const Pose& a = before->X_WB[r.base_body];
          const Pose& b = snap.X_WB[r.base_body];
          const Eigen::AngleAxisd d(b.rotation() * a.rotation().transpose());
          V.head<3>() = d.axis() * d.angle() / h;
          V.tail<3>() = (b.translation() - a.translation()) / h;
          qvel.assign(static_cast<size_t>(model.nv), 0.0);
          for (int j : r.joints) {
            const JointInfo& ji = model.joints[j];
            qvel[ji.dof_adr] = (snap.qpos[ji.qpos_adr] - before->qpos[ji.qpos_adr]) / h;
          }
        }
        bag.Write(r.odom_topic, stamp,
                  OdometryToRos(snap.X_WB[r.base_body], V, r.odom_frame, r.base_frame, stamp));
        bag.Write(r.joint_states_topic, stamp,
                  JointStateToRos(model, r.joints, snap.qpos, qvel, {}, stamp));
        count(r.odom_topic);
        count(r.joint_states_topic);
      }
      previous = snap;
      previous_row = row;
    }
  }
  CheckExportStop(stop_request);
  target.Finish();
  for (const auto& [topic, n] : summary.counts) summary.messages += n;
  return summary;
}

}  // namespace

}  // namespace penumbra
