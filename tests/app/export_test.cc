// `penumbra export` end to end on a short run of a small world: a camera looking at a wall at
// a known distance (TUM depth = 5000 per metre at the centre pixel, within 1 unit), a second
// camera at another wall, an IMU on the same rigid body (EuRoC T_BS and ground truth from the
// run's rig.json and imu/<name>_truth.csv), KITTI poses of a static camera; bad input exits 2.

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <sstream>

#include "app/child_process.h"
#include "common/temp_dir.h"
#include "penumbra/core/pose.h"

namespace penumbra {
namespace {

namespace fs = std::filesystem;
using testing::ReadAll;
using testing::RunPenumbra;

// walls: the front face of "near" at x = 1.5 m, of "far" at x = -2.25 m; the rig body (no
// joint: welded to the world) at (0, 0, 1) holds both cameras and the IMU; a third camera sits
// on "tip", welded to "arm", which turns on a vertical hinge at 2 rad/s (keyframe "spin"; no
// gravity torque, no damping, no contact), with a second IMU "spin" 0.05 m beyond the tip, 0.15 m
// from the axis
constexpr char kMjcf[] = R"(
<mujoco model="walls">
  <option timestep="0.005"/>
  <worldbody>
    <geom name="near" type="box" pos="1.55 0 1" size="0.05 3 3" rgba="0.7 0.7 0.7 1"/>
    <geom name="far" type="box" pos="-2.3 0 1" size="0.05 3 3" rgba="0.4 0.5 0.7 1"/>
    <body name="rig" pos="0 0 1">
      <geom name="box" type="box" pos="0 0 -0.2" size="0.02 0.02 0.02" contype="0" conaffinity="0"/>
      <body name="arm" pos="0 0.3 0">
        <joint name="swivel" type="hinge" axis="0 0 1"/>
        <geom name="arm" type="box" size="0.02 0.02 0.02" contype="0" conaffinity="0"/>
        <body name="tip" pos="0.1 0 0">
          <geom name="tip" type="sphere" size="0.01" contype="0" conaffinity="0"/>
        </body>
      </body>
    </body>
  </worldbody>
  <keyframe><key name="spin" qvel="2"/></keyframe>
</mujoco>)";

constexpr char kWorld[] = R"(seed: 3
duration_sec: 0.5
models:
  - {name: scene, file: walls.xml, initial_keyframe: spin}
lights:
  - {name: sun, type: sun, direction: [0.3, 0.4, -1], illuminance_lux: 400}
mjcf_cameras: {enabled: false}
cameras:
  - name: front
    attach: scene/rig
    pose: {xyz: [0, 0, 0], rpy_deg: [0, 0, 0]}
    width: 32
    height: 24
    fovy_deg: 60
    rate_hz: 10
    outputs: [rgb, depth]
  - name: back
    attach: scene/rig
    pose: {xyz: [0, 0, 0], rpy_deg: [0, 0, 180]}
    width: 32
    height: 24
    fovy_deg: 60
    rate_hz: 10
    outputs: [rgb, depth]
  - name: arm_cam
    attach: scene/tip
    pose: {xyz: [0, 0, 0.05], rpy_deg: [0, 0, 0]}
    width: 16
    height: 12
    rate_hz: 10
    outputs: [rgb]
sensors:
  - name: imu
    type: imu
    body: scene/rig
    pose: {xyz: [0.1, 0, -0.05], rpy_deg: [0, 0, 90]}
    preset: consumer_mems
    rate_hz: 100
  - name: spin
    type: imu
    body: scene/tip
    pose: {xyz: [0.05, 0, 0], rpy_deg: [0, 0, 0]}
    preset: ideal
    noise: {gyro_random_walk: 0.01, accel_random_walk: 0.01}
    rate_hz: 100
)";

std::vector<std::string> Lines(const fs::path& p) {
  std::istringstream in(ReadAll(p));
  std::vector<std::string> out;
  std::string line;
  while (std::getline(in, line)) out.push_back(line);
  return out;
}

class ExportCommandTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new testing::TempDir();
    dir_->Write("walls.xml", kMjcf);
    const std::string world = dir_->Write("world.yaml", kWorld);
    const testing::ProcessResult r =
        RunPenumbra({"run", world, "--out", (dir_->path() / "run").string(), "--record",
                     (dir_->path() / "run.plog").string(), "--quiet"},
                    dir_->path());
    ASSERT_EQ(r.exit_code, 0) << r.err;
  }
  static void TearDownTestSuite() {
    delete dir_;
    dir_ = nullptr;
  }
  testing::ProcessResult Export(const std::string& format, const fs::path& out,
                                std::vector<std::string> extra = {}) {
    std::vector<std::string> args = {"export", run().string(), "--format",
                                     format,   "--out",        out.string()};
    args.insert(args.end(), extra.begin(), extra.end());
    return RunPenumbra(args, dir_->path());
  }
  static fs::path run() { return dir_->path() / "run"; }
  static testing::TempDir* dir_;
  testing::TempDir out_;
};
testing::TempDir* ExportCommandTest::dir_ = nullptr;

TEST_F(ExportCommandTest, RunWritesRigAndImuTruth) {
  const nlohmann::json rig = nlohmann::json::parse(ReadAll(run() / "rig.json"));
  EXPECT_EQ(rig["cameras"]["front"]["body"], "scene/rig");
  EXPECT_EQ(rig["cameras"]["front"]["rigid_body"], "world");  // the rig has no joint
  EXPECT_EQ(rig["imus"]["imu"]["rigid_body"], "world");
  // a camera on a body welded to a jointed one moves with the jointed one
  EXPECT_EQ(rig["cameras"]["arm_cam"]["body"], "scene/tip");
  EXPECT_EQ(rig["cameras"]["arm_cam"]["rigid_body"], "scene/arm");
  const std::vector<double> arm_xyz = rig["cameras"]["arm_cam"]["X_RS"]["xyz"];
  EXPECT_NEAR(arm_xyz[0], 0.1, 1e-12);
  EXPECT_NEAR(arm_xyz[2], 0.05, 1e-12);
  EXPECT_EQ(rig["imus"]["imu"]["rate_hz"], 100.0);
  const std::vector<double> xyz = rig["imus"]["imu"]["X_RS"]["xyz"];
  EXPECT_NEAR(xyz[0], 0.1, 1e-12);
  EXPECT_NEAR(xyz[2], 1 - 0.05, 1e-12);
  const auto samples = Lines(run() / "imu" / "imu.csv");
  const auto truth = Lines(run() / "imu" / "imu_truth.csv");
  ASSERT_GT(samples.size(), 40u);
  ASSERT_EQ(truth.size(), samples.size());
  // the static IMU: at (0.1, 0, 0.95), yawed 90 deg, not moving
  std::istringstream row(truth[5]);
  std::vector<double> v;
  for (std::string f; std::getline(row, f, ',');) v.push_back(std::stod(f));
  ASSERT_EQ(v.size(), 18u);
  EXPECT_NEAR(v[2], 0.1, 1e-9);
  EXPECT_NEAR(v[4], 0.95, 1e-9);
  EXPECT_NEAR(v[5], std::cos(M_PI / 4), 1e-8);  // qw
  EXPECT_NEAR(v[8], std::sin(M_PI / 4), 1e-8);  // qz
  for (int i = 9; i < 12; ++i) EXPECT_NEAR(v[i], 0, 1e-9);
  // the spinning IMU: velocity of its own origin, 0.15 m from the axis at 2 rad/s: 0.3 m/s,
  // horizontal, perpendicular to the radius (its body's origin, 0.1 m out, moves at 0.2 m/s)
  const auto spin = Lines(run() / "imu" / "spin_truth.csv");
  ASSERT_GT(spin.size(), 40u);
  for (size_t k = 1; k < spin.size(); k += 7) {
    std::istringstream in(spin[k]);
    std::vector<double> s;
    for (std::string f; std::getline(in, f, ',');) s.push_back(std::stod(f));
    ASSERT_EQ(s.size(), 18u);
    const Eigen::Vector3d radius(s[2] - 0, s[3] - 0.3, s[4] - 1);
    const Eigen::Vector3d vel(s[9], s[10], s[11]);
    EXPECT_NEAR(radius.norm(), 0.15, 1e-6) << spin[k];
    EXPECT_NEAR(vel.norm(), 0.3, 1e-6) << spin[k];
    EXPECT_NEAR(vel.dot(radius), 0, 1e-6) << spin[k];
    EXPECT_NEAR(vel.z(), 0, 1e-9) << spin[k];
  }
  // its noise is bias only (random walk, no white noise): each sample is the true value plus
  // the bias its truth row gives; the gyro's true value is (0, 0, 2) rad/s
  const auto spin_samples = Lines(run() / "imu" / "spin.csv");
  ASSERT_EQ(spin_samples.size(), spin.size());
  double largest_bias = 0;
  for (size_t k = 1; k < spin.size(); ++k) {
    std::istringstream a(spin_samples[k]), b(spin[k]);
    std::vector<double> m, t;
    for (std::string f; std::getline(a, f, ',');) m.push_back(std::stod(f));
    for (std::string f; std::getline(b, f, ',');) t.push_back(std::stod(f));
    ASSERT_EQ(m.size(), 9u);
    for (int i = 0; i < 3; ++i) {
      EXPECT_NEAR(m[6 + i] - t[12 + i], i == 2 ? 2.0 : 0.0, 1e-6) << "sample " << k;
      largest_bias = std::max(largest_bias, std::abs(t[12 + i]));
    }
  }
  EXPECT_GT(largest_bias, 1e-3);
}

TEST_F(ExportCommandTest, TumDepthIs5000PerMetreAtAKnownWallDistance) {
  const fs::path out = out_.path() / "tum";
  for (const auto& [camera, d] : {std::pair<std::string, double>{"front", 1.5}, {"back", 2.25}}) {
    const fs::path o = out / camera;
    const testing::ProcessResult r = Export("tum", o, {"--camera", camera});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const auto lines = Lines(o / "depth.txt");
    ASSERT_GE(lines.size(), 3u + 5u);  // 5 or 6 frames in 0.5 s at 10 Hz
    for (size_t i = 3; i < lines.size(); ++i) {
      const std::string file = lines[i].substr(lines[i].find(' ') + 1);
      const cv::Mat depth = cv::imread((o / file).string(), cv::IMREAD_UNCHANGED);
      ASSERT_EQ(depth.type(), CV_16UC1) << file;
      const double v = depth.at<uint16_t>(depth.rows / 2, depth.cols / 2);
      EXPECT_NEAR(v, 5000 * d, 1.0) << camera << " " << file;
    }
    // camera.txt: "fx fy cx cy d0 .. d4" of the run's camera_info.json
    const auto cam = Lines(o / "camera.txt");
    ASSERT_EQ(cam.size(), 4u);
    EXPECT_EQ(cam[0].rfind("# camera intrinsics: 32 x 24 pixels", 0), 0u) << cam[0];
    std::istringstream row(cam[3]);
    std::vector<double> v;
    for (double x = 0; row >> x;) v.push_back(x);
    ASSERT_EQ(v.size(), 9u) << cam[3];
    const nlohmann::json info = nlohmann::json::parse(ReadAll(run() / "camera_info.json"));
    const std::vector<double> K = info[camera]["K"];
    EXPECT_NEAR(v[0], K[0], 1e-9);
    EXPECT_NEAR(v[1], K[4], 1e-9);
    EXPECT_NEAR(v[2], K[2], 1e-9);
    EXPECT_NEAR(v[3], K[5], 1e-9);
    EXPECT_NEAR(v[1], 12 / std::tan(M_PI / 6), 1e-6);  // fovy 60 deg over 24 pixels
    for (int i = 4; i < 9; ++i) EXPECT_EQ(v[i], 0) << i;
  }
}

TEST_F(ExportCommandTest, EurocExtrinsicsAndGroundTruthFromTheRun) {
  const fs::path out = out_.path() / "euroc";
  const testing::ProcessResult r =
      Export("euroc", out, {"--camera", "front", "--camera2", "back", "--imu", "imu"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  // T_BS of cam0: the optical frame of "front" in the IMU frame
  Pose X_RI = PoseFromXyzRpyDeg({0.1, 0, -0.05}, {0, 0, 90});
  Pose X_RC = Pose::Identity();
  X_RC.linear() = RotationBodyFromOptical();
  const Eigen::Matrix4d expected = (X_RI.inverse() * X_RC).matrix();
  const std::string yaml = ReadAll(out / "mav0/cam0/sensor.yaml");
  std::string data = yaml.substr(yaml.find("data: [") + 7);
  data = data.substr(0, data.find(']'));
  for (char& c : data)
    if (c == ',') c = ' ';
  std::istringstream in(data);
  for (int i = 0; i < 16; ++i) {
    double v = 0;
    ASSERT_TRUE(in >> v) << yaml;
    EXPECT_NEAR(v, expected(i / 4, i % 4), 1e-9) << i;
  }
  EXPECT_NE(yaml.find("rate_hz: 10\n"), std::string::npos) << yaml;
  EXPECT_TRUE(fs::exists(out / "mav0/cam1/data.csv"));
  // ground truth: the IMU at (0.1, 0, 0.95), at rest; as many rows as IMU samples
  const auto gt = Lines(out / "mav0/state_groundtruth_estimate0/data.csv");
  const auto imu = Lines(out / "mav0/imu0/data.csv");
  EXPECT_EQ(gt.size(), imu.size());
  EXPECT_EQ(imu.size(), Lines(run() / "imu" / "imu.csv").size());
  std::istringstream row(gt[3]);
  std::vector<double> v;
  for (std::string f; std::getline(row, f, ',');) v.push_back(std::stod(f));
  ASSERT_EQ(v.size(), 17u);
  EXPECT_NEAR(v[1], 0.1, 1e-9);
  EXPECT_NEAR(v[3], 0.95, 1e-9);
  // the accelerometer of a resting IMU reads +g along its z (noise and bias are small)
  std::istringstream s(imu[3]);
  std::vector<double> a;
  for (std::string f; std::getline(s, f, ',');) a.push_back(std::stod(f));
  ASSERT_EQ(a.size(), 7u);
  EXPECT_NEAR(a[6], 9.81, 0.05);
}

TEST_F(ExportCommandTest, KittiPosesOfAStaticCameraAreIdentity) {
  const fs::path out = out_.path() / "kitti";
  const testing::ProcessResult r =
      Export("kitti", out, {"--camera", "front", "--camera2", "back", "--sequence", "07"});
  // "back" looks the other way: not KITTI's parallel pair, but a rigid one (P1 with a rotation)
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto poses = Lines(out / "poses/07.txt");
  ASSERT_GE(poses.size(), 5u);
  for (const std::string& line : poses) {
    std::istringstream in(line);
    std::vector<double> v;
    for (double x; in >> x;) v.push_back(x);
    ASSERT_EQ(v.size(), 12u);
    for (int i = 0; i < 12; ++i) EXPECT_NEAR(v[i], (i == 0 || i == 5 || i == 10) ? 1 : 0, 1e-9);
  }
  EXPECT_EQ(Lines(out / "sequences/07/times.txt").size(), poses.size());
}

TEST_F(ExportCommandTest, BadInputExitsTwoWithAMessage) {
  // several cameras, none named
  testing::ProcessResult r = Export("tum", out_.path() / "a");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("--camera"), std::string::npos) << r.err;
  // a non-empty output folder
  fs::create_directories(out_.path() / "full");
  std::ofstream(out_.path() / "full" / "x") << "x";
  r = Export("tum", out_.path() / "full", {"--camera", "front"});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("not empty"), std::string::npos) << r.err;
  // EuRoC with two IMUs and none named
  r = Export("euroc", out_.path() / "e", {"--camera", "front"});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("--imu"), std::string::npos) << r.err;
  // EuRoC: a camera that moves relative to the IMU has no constant T_BS
  r = Export("euroc", out_.path() / "d", {"--camera", "arm_cam", "--imu", "imu"});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("move relative to each other"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out_.path() / "d"));
  // an unknown format (CLI usage error) and a run log
  r = Export("rosbag", out_.path() / "b");
  EXPECT_EQ(r.exit_code, 2);
  r = RunPenumbra({"export", (out_.path() / "x.plog").string(), "--format", "tum", "--out",
                   (out_.path() / "c").string()},
                  out_.path());
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("no such run log"), std::string::npos) << r.err;
  // --world only for a run log
  r = Export("tum", out_.path() / "w", {"--camera", "front", "--world", "x.yaml"});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("only for a run log"), std::string::npos) << r.err;
}

// EuRoC of a world without an IMU says so, naming what is missing, before a run log is replayed
// (no replay line, no replay folder) and before anything of a run folder is written
TEST_F(ExportCommandTest, EurocWithoutAnImuIsRefusedBeforeTheReplay) {
  std::string text = kWorld;
  text.erase(text.find("sensors:"));
  testing::TempDir world_dir;
  world_dir.Write("walls.xml", kMjcf);
  const std::string world = world_dir.Write("no_imu.yaml", text);
  const fs::path log = world_dir.path() / "no_imu.plog";
  testing::ProcessResult r =
      RunPenumbra({"run", world, "--duration", "0.2", "--out", (world_dir.path() / "run").string(),
                   "--record", log.string(), "--quiet"},
                  world_dir.path());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  auto no_replay = [&](const testing::ProcessResult& p) {
    EXPECT_EQ(p.out.find("replaying"), std::string::npos) << p.out;
    EXPECT_EQ(p.err.find("replaying"), std::string::npos) << p.err;
    for (const auto& e : fs::directory_iterator(out_.path()))
      ADD_FAILURE() << "left behind: " << e.path();
  };
  const fs::path out = out_.path() / "euroc";
  r = RunPenumbra(
      {"export", log.string(), "--format", "euroc", "--camera", "front", "--out", out.string()},
      world_dir.path());
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("EuRoC needs an IMU (imu0) and the run log's world"), std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find("no_imu.yaml) has none"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("type: imu"), std::string::npos) << r.err;
  no_replay(r);
  // the run folder of the same world
  r = RunPenumbra({"export", (world_dir.path() / "run").string(), "--format", "euroc", "--camera",
                   "front", "--out", out.string()},
                  world_dir.path());
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("the run has no IMU; EuRoC needs one (imu0)"), std::string::npos) << r.err;
  no_replay(r);
  // a log with two IMUs: an --imu it does not have, and none named, before the replay too
  const fs::path two = dir_->path() / "run.plog";
  r = RunPenumbra({"export", two.string(), "--format", "euroc", "--camera", "front", "--imu",
                   "nope", "--out", out.string()},
                  world_dir.path());
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("'nope' is not an IMU of the run log's world"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("expected one of: imu, spin"), std::string::npos) << r.err;
  no_replay(r);
  r = RunPenumbra(
      {"export", two.string(), "--format", "euroc", "--camera", "front", "--out", out.string()},
      world_dir.path());
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("has 2 IMUs; expected one named with --imu (imu, spin)"), std::string::npos)
      << r.err;
  no_replay(r);
}

// a run log is replayed with the recorded conditions and exported with --depth ground-truth:
// the dataset is the one the run's own folder gives (the run's camera has no depth_noise),
// file for file, and the temporary replay folder is gone
TEST_F(ExportCommandTest, ARunLogExportsTheSameDatasetAsItsRunFolder) {
  ASSERT_EQ(Export("tum", out_.path() / "from_run", {"--camera", "front"}).exit_code, 0);
  const testing::ProcessResult r = RunPenumbra(
      {"export", (dir_->path() / "run.plog").string(), "--format", "tum", "--out",
       (out_.path() / "from_log").string(), "--camera", "front", "--depth", "ground-truth"},
      dir_->path());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const std::string log_from_dataset =
      fs::relative(dir_->path() / "run.plog", out_.path() / "from_log").string();
  std::vector<std::string> names;
  for (const auto& e : fs::recursive_directory_iterator(out_.path() / "from_run")) {
    if (!e.is_regular_file()) continue;
    const fs::path rel = fs::relative(e.path(), out_.path() / "from_run");
    names.push_back(rel.string());
    if (rel == "penumbra_export.yaml") continue;  // names the source and the depth: below
    // the lists name their source relative to the dataset: the run folder, or the log
    std::string a = ReadAll(e.path()), b = ReadAll(out_.path() / "from_log" / rel);
    const std::string run_line =
        "# file: '" + fs::relative(run(), out_.path() / "from_run").string() + "'\n";
    const std::string log_line = "# file: '" + log_from_dataset + "'\n";
    if (const size_t at = a.find(run_line); at != std::string::npos) {
      a.replace(at, run_line.size(), log_line);
    }
    EXPECT_EQ(a, b) << rel;
  }
  EXPECT_GT(names.size(), 10u);  // 6 rgb + 6 depth + 4 lists
  // no absolute path in any of the dataset's text files
  for (const char* d : {"from_run", "from_log"})
    for (const auto& e : fs::recursive_directory_iterator(out_.path() / d))
      if (e.is_regular_file() && e.path().extension() != ".png") {
        const std::string text = ReadAll(e.path());
        EXPECT_EQ(text.find(dir_->path().string()), std::string::npos) << e.path();
        EXPECT_EQ(text.find(out_.path().string()), std::string::npos) << e.path();
      }
  size_t log_files = 0;
  for (const auto& e : fs::recursive_directory_iterator(out_.path() / "from_log"))
    log_files += e.is_regular_file();
  EXPECT_EQ(log_files, names.size());
  EXPECT_FALSE(fs::exists(out_.path() / "from_log.replay-tmp"));
  const std::string meta_run = ReadAll(out_.path() / "from_run" / "penumbra_export.yaml");
  const std::string meta_log = ReadAll(out_.path() / "from_log" / "penumbra_export.yaml");
  EXPECT_NE(meta_run.find("depth:\n  source: as_recorded\n"), std::string::npos) << meta_run;
  EXPECT_NE(meta_log.find("depth:\n  source: ground_truth\n"), std::string::npos) << meta_log;
  EXPECT_NE(meta_log.find("source: '" + log_from_dataset + "'"), std::string::npos) << meta_log;
  EXPECT_TRUE(fs::is_regular_file(out_.path() / "from_log" / log_from_dataset));
}

// the README's replay -> export path: by default the replay renders the depth through the
// benchmarks' sensor model (realsense_d435: sigma_z = z^2 0.08 / (fx 0.05), fx the depth image's
// focal length in pixels), so the exported depth differs from the ground truth by that
// model's statistics; the same seed gives the same dataset; a run folder's depth is exported
// as the run wrote it and --depth is refused there
TEST_F(ExportCommandTest, ARunLogExportsDepthThroughTheBenchmarksSensorModel) {
  const fs::path log = dir_->path() / "run.plog";
  auto export_log = [&](const std::string& name, std::vector<std::string> extra) {
    std::vector<std::string> args = {"export",   log.string(), "--format",
                                     "tum",      "--out",      (out_.path() / name).string(),
                                     "--camera", "front"};
    args.insert(args.end(), extra.begin(), extra.end());
    return RunPenumbra(args, dir_->path());
  };
  ASSERT_EQ(export_log("sensor", {}).exit_code, 0);
  ASSERT_EQ(export_log("sensor_again", {"--depth", "sensor"}).exit_code, 0);
  ASSERT_EQ(export_log("truth", {"--depth", "ground-truth"}).exit_code, 0);
  const std::string meta = ReadAll(out_.path() / "sensor" / "penumbra_export.yaml");
  EXPECT_NE(meta.find("depth:\n  source: sensor_model\n  model: realsense_d435\n"),
            std::string::npos)
      << meta;
  // the wall is fronto-parallel at 1.5 m: every pixel's z is 1.5 m (7500 in TUM units); the
  // 32 x 24 camera with fovy 60 deg has fx = fy = 12 / tan(30 deg) = 20.78 px. the plain wall
  // in soft light (a 400 lux sun plus the sky) is textured by the D435's projector (a brighter
  // sun washes the dots out: holes); column 0 is the stereo model's left invalid band (fx b / z =
  // 0.69 px)
  const double fx = 12.0 / std::tan(30.0 * M_PI / 180.0);
  const double sigma_m = 1.5 * 1.5 * 0.08 / (fx * 0.05);  // 0.1732 m
  const auto lines = Lines(out_.path() / "truth" / "depth.txt");
  ASSERT_GE(lines.size(), 3u + 5u);
  double sum = 0, sum2 = 0;
  int64_t n = 0, holes = 0, band = 0, band_holes = 0;
  for (size_t i = 3; i < lines.size(); ++i) {
    const std::string file = lines[i].substr(lines[i].find(' ') + 1);
    const cv::Mat truth = cv::imread((out_.path() / "truth" / file).string(), cv::IMREAD_UNCHANGED);
    const cv::Mat noisy =
        cv::imread((out_.path() / "sensor" / file).string(), cv::IMREAD_UNCHANGED);
    const cv::Mat again =
        cv::imread((out_.path() / "sensor_again" / file).string(), cv::IMREAD_UNCHANGED);
    ASSERT_EQ(noisy.type(), CV_16UC1) << file;
    EXPECT_EQ(cv::norm(noisy, again, cv::NORM_INF), 0.0) << file;  // deterministic
    for (int v = 0; v < truth.rows; ++v)
      for (int u = 0; u < truth.cols; ++u) {
        const double t = truth.at<uint16_t>(v, u), z = noisy.at<uint16_t>(v, u);
        EXPECT_NEAR(t, 7500, 1.0);  // ground truth: exact
        if (u == 0) {
          ++band;
          band_holes += z == 0;
          continue;
        }
        if (z == 0) {
          ++holes;
          continue;
        }
        const double e = (z - t) / 5000.0;
        sum += e;
        sum2 += e * e;
        ++n;
      }
  }
  ASSERT_GT(n, 2000);
  EXPECT_LT(holes, n / 100);
  EXPECT_GT(band_holes, band / 2);  // lateral jitter reads some from column 1
  const double mean = sum / n, std = std::sqrt(sum2 / n - mean * mean);
  // the model's axial sigma within 10 % (n > 2000 samples: the estimate's own spread is ~2 %);
  // the mean within 4 standard errors of 0
  EXPECT_NEAR(std, sigma_m, 0.1 * sigma_m) << "n " << n;
  EXPECT_NEAR(mean, 0.0, 4 * sigma_m / std::sqrt(static_cast<double>(n)));
  // a run folder: exported as recorded; --depth is a run-log option
  const testing::ProcessResult folder =
      Export("tum", out_.path() / "folder", {"--camera", "front", "--depth", "sensor"});
  EXPECT_EQ(folder.exit_code, 2);
  EXPECT_NE(folder.err.find("--depth: only for a run log (.plog) input"), std::string::npos)
      << folder.err;
}

}  // namespace
}  // namespace penumbra
