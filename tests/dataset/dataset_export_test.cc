// dataset export (dataset/dataset_export.h) of a hand-made run folder (fake_run.h), checked
// against the formats' published rules: TUM RGB-D (file formats page), EuRoC/ASL (Burri et al.
// 2016), KITTI odometry (devkit readme): column counts, units, strictly increasing timestamps,
// file names matching the lists, unit quaternions, depth scale 5000 per metre.

#include "penumbra/dataset/dataset_export.h"

#include <fcntl.h>
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/file.h>
#include <sys/wait.h>
#include <unistd.h>

#include <Eigen/Geometry>
#include <fstream>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <set>
#include <sstream>

#include "common/temp_dir.h"
#include "dataset/fake_run.h"
#include "penumbra/core/error.h"
#include "penumbra/dataset/euroc_export.h"
#include "penumbra/dataset/image_convert.h"
#include "penumbra/dataset/kitti_export.h"
#include "penumbra/dataset/tum_export.h"

namespace penumbra {
namespace {

namespace fs = std::filesystem;
using testing::ReadAll;
using testing::ReadBytes;
using testing::TempDir;

std::vector<std::string> Lines(const fs::path& p) {
  std::istringstream in(ReadAll(p));
  std::vector<std::string> out;
  std::string line;
  while (std::getline(in, line)) out.push_back(line);
  return out;
}

std::vector<std::string> Fields(const std::string& line, char sep) {
  std::vector<std::string> out;
  std::istringstream in(line);
  std::string f;
  if (sep == ' ') {
    while (in >> f) out.push_back(f);
  } else {
    while (std::getline(in, f, sep)) out.push_back(f);
  }
  return out;
}

// the data lines of a TUM list (no '#' lines), split at spaces
std::vector<std::vector<std::string>> TumRows(const fs::path& p, int header_lines) {
  const std::vector<std::string> lines = Lines(p);
  std::vector<std::vector<std::string>> rows;
  for (size_t i = 0; i < lines.size(); ++i) {
    if (static_cast<int>(i) < header_lines) {
      EXPECT_EQ(lines[i].rfind("# ", 0), 0u) << p << " line " << i + 1;
      continue;
    }
    EXPECT_NE(lines[i].front(), '#') << p;
    rows.push_back(Fields(lines[i], ' '));
  }
  return rows;
}

Pose PoseFromKittiRow(const std::vector<std::string>& f) {
  Eigen::Matrix4d M = Eigen::Matrix4d::Identity();
  for (int i = 0; i < 12; ++i) M(i / 4, i % 4) = std::stod(f[i]);
  Pose X;
  X.matrix() = M;
  return X;
}

class DatasetExportTest : public ::testing::Test {
 protected:
  void SetUp() override {
    run_ = tmp_.path() / "run";
    fs::create_directories(run_);
  }
  DatasetExportSummary Export(DatasetFormat format, const std::string& camera2 = "") {
    DatasetExportOptions o;
    o.format = format;
    o.out_dir = out();
    o.camera = "cam";
    o.camera2 = camera2;
    return ExportDataset(RunFolder(run_), o);
  }
  fs::path out() const { return tmp_.path() / "out"; }
  TempDir tmp_;
  fs::path run_;
};

TEST(TumDepth, FiveUnitsPerMillimetreZeroWhenItDoesNotFit) {
  EXPECT_EQ(TumDepthFromMillimetres(0), 0);
  EXPECT_EQ(TumDepthFromMillimetres(1), 5);
  EXPECT_EQ(TumDepthFromMillimetres(1000), 5000);  // 1 m = 5000
  EXPECT_EQ(TumDepthFromMillimetres(2000), 10000);
  EXPECT_EQ(TumDepthFromMillimetres(13107), 65535);
  EXPECT_EQ(TumDepthFromMillimetres(13108), 0);
  EXPECT_EQ(TumDepthFromMillimetres(65535), 0);
}

TEST_F(DatasetExportTest, TumListsImagesDepthScaleAndGroundTruth) {
  testing::WriteFakeRun(run_);
  const DatasetExportSummary s = Export(DatasetFormat::kTum);
  EXPECT_EQ(s.frames, 4);
  EXPECT_EQ(s.depth_beyond_range, 4 * 2);  // 13108 and 65535 in every frame
  // rgb.txt / depth.txt: 3 '#' lines, then "timestamp filename", strictly increasing
  for (const char* kind : {"rgb", "depth"}) {
    const auto rows = TumRows(out() / (std::string(kind) + ".txt"), 3);
    ASSERT_EQ(rows.size(), 4u);
    double previous = -1;
    for (size_t i = 0; i < rows.size(); ++i) {
      ASSERT_EQ(rows[i].size(), 2u);
      const double t = std::stod(rows[i][0]);
      EXPECT_GT(t, previous);
      previous = t;
      EXPECT_NEAR(t, 0.05 * i, 1e-9);
      EXPECT_EQ(rows[i][1], std::string(kind) + "/" + rows[i][0] + ".png");
      EXPECT_TRUE(fs::is_regular_file(out() / rows[i][1])) << rows[i][1];
    }
  }
  EXPECT_EQ(ReadAll(out() / "rgb.txt").substr(0, 16), "# color images\n#");
  EXPECT_EQ(ReadAll(out() / "depth.txt").substr(0, 14), "# depth maps\n#");
  // colour images byte for byte; depth 16-bit at 5000 per metre, 0 = no data
  EXPECT_EQ(ReadBytes(out() / "rgb/0.050000.png"), ReadBytes(run_ / "cam/rgb/000001.png"));
  for (int i = 0; i < 4; ++i) {
    const cv::Mat d = cv::imread((out() / "depth" / (TumTimestamp(0.05 * i) + ".png")).string(),
                                 cv::IMREAD_UNCHANGED);
    ASSERT_EQ(d.type(), CV_16UC1);
    ASSERT_EQ(d.cols, 8);
    for (int y = 0; y < 6; ++y)
      for (int x = 0; x < 8; ++x) {
        const int mm = testing::FakeDepthMm(x, y, i);
        EXPECT_EQ(d.at<uint16_t>(y, x), mm > 13107 ? 0 : 5 * mm) << x << "," << y;
      }
  }
  // groundtruth.txt: "timestamp tx ty tz qx qy qz qw" of the optical frame in the world
  const auto truth = TumRows(out() / "groundtruth.txt", 3);
  ASSERT_EQ(truth.size(), 4u);
  for (size_t i = 0; i < truth.size(); ++i) {
    ASSERT_EQ(truth[i].size(), 8u);
    const Pose X = testing::FakeCameraPose(static_cast<int>(i));
    const Eigen::Quaterniond q(std::stod(truth[i][7]), std::stod(truth[i][4]),
                               std::stod(truth[i][5]), std::stod(truth[i][6]));
    EXPECT_NEAR(q.norm(), 1.0, 1e-8);
    EXPECT_LT(Eigen::AngleAxisd(q.toRotationMatrix() * X.linear().transpose()).angle(), 1e-8);
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(std::stod(truth[i][1 + k]), X.translation()[k], 1e-9);
  }
  // associations.txt as associate.py prints it: rgb stamp, rgb file, depth stamp, depth file
  const auto assoc = TumRows(out() / "associations.txt", 0);
  ASSERT_EQ(assoc.size(), 4u);
  for (const auto& a : assoc) {
    ASSERT_EQ(a.size(), 4u);
    EXPECT_EQ(a[0], a[2]);
    EXPECT_EQ(a[1], "rgb/" + a[0] + ".png");
    EXPECT_EQ(a[3], "depth/" + a[2] + ".png");
  }
}

// camera.txt: "fx fy cx cy d0 d1 d2 d3 d4" as the benchmark's "File Formats" page lists its
// Kinects' intrinsics, from camera_info.json (K row-major, D = k1 k2 p1 p2 k3)
TEST_F(DatasetExportTest, TumCameraTxtCarriesTheIntrinsicsAndDistortion) {
  testing::WriteFakeRun(run_);
  std::ofstream(run_ / "camera_info.json")
      << R"({"cam": {"frame_id": "cam/optical", "width": 8, "height": 6,)"
      << R"( "distortion_model": "plumb_bob", "D": [0.125, -0.25, 0.001, -0.002, 0.5],)"
      << R"( "K": [10.5, 0, 4.25, 0, 11.75, 3.5, 0, 0, 1]}})";
  Export(DatasetFormat::kTum);
  const auto rows = TumRows(out() / "camera.txt", 3);
  ASSERT_EQ(rows.size(), 1u);
  const std::vector<double> expected = {10.5, 11.75, 4.25, 3.5, 0.125, -0.25, 0.001, -0.002, 0.5};
  ASSERT_EQ(rows[0].size(), expected.size());
  for (size_t i = 0; i < expected.size(); ++i) EXPECT_EQ(std::stod(rows[0][i]), expected[i]) << i;
  const std::vector<std::string> lines = Lines(out() / "camera.txt");
  EXPECT_EQ(lines[0].rfind("# camera intrinsics: 8 x 6 pixels", 0), 0u) << lines[0];
  EXPECT_EQ(lines[2], "# fx fy cx cy d0 d1 d2 d3 d4");
}

// no absolute path is written into a dataset: its files name the run folder relative to the
// dataset's own folder, a path that still leads there
TEST_F(DatasetExportTest, TheDatasetNamesItsSourceRelativeToItself) {
  testing::WriteFakeRun(run_);
  Export(DatasetFormat::kTum);
  EXPECT_EQ(Lines(out() / "rgb.txt")[1], "# file: '../run'");
  EXPECT_EQ(Lines(out() / "camera.txt")[1], "# file: '../run'");
  EXPECT_NE(ReadAll(out() / "penumbra_export.yaml").find("\nsource: '../run'\n"),
            std::string::npos);
  EXPECT_TRUE(fs::is_regular_file(out() / "../run" / "camera_info.json"));
  for (const auto& e : fs::recursive_directory_iterator(out())) {
    if (!e.is_regular_file() || e.path().extension() == ".png") continue;
    EXPECT_EQ(ReadAll(e.path()).find(tmp_.path().string()), std::string::npos) << e.path();
  }
  EXPECT_EQ(PathRelativeTo("/a/b/run", "/a/c/out"), "../../b/run");
  EXPECT_EQ(PathRelativeTo("/a/b/run", "/a/b/run/x"), "..");
  EXPECT_EQ(PathRelativeTo("/a/b/run.plog", "/a/b/run"), "../run.plog");
}

TEST_F(DatasetExportTest, TumRefusesACameraWithoutDepthAndLeavesNoOutput) {
  testing::FakeRunSpec spec;
  spec.depth = false;
  testing::WriteFakeRun(run_, spec);
  try {
    Export(DatasetFormat::kTum);
    FAIL() << "expected a ConfigError";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("no depth images"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(out()));
}

TEST_F(DatasetExportTest, RefusesANonEmptyOutputFolderAndUnknownCameras) {
  testing::WriteFakeRun(run_);
  fs::create_directories(out());
  std::ofstream(out() / "keep.txt") << "mine";
  EXPECT_THROW(Export(DatasetFormat::kTum), ConfigError);
  EXPECT_EQ(ReadAll(out() / "keep.txt"), "mine");
  DatasetExportOptions o;
  o.out_dir = tmp_.path() / "out2";
  o.camera = "nope";
  try {
    ExportDataset(RunFolder(run_), o);
    FAIL() << "expected a ConfigError";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("expected one of: cam, cam/right"), std::string::npos)
        << e.what();
  }
  // two cameras and none named
  o.camera = "";
  EXPECT_THROW(ExportDataset(RunFolder(run_), o), ConfigError);
  EXPECT_THROW(RunFolder(tmp_.path() / "missing"), ConfigError);
}

TEST_F(DatasetExportTest, BadFramesCsvNamesFileLineAndColumn) {
  testing::WriteFakeRun(run_);
  std::ofstream(run_ / "cam" / "frames.csv") << "frame,time_sec,x,y,z,qw,qx,qy,qz\n"
                                                "0,0,0,0,0,1,0,0,0\n"
                                                "1,0.1,0,zero,0,1,0,0,0\n";
  try {
    RunFolder(run_).ReadCamera("cam");
    FAIL() << "expected a ConfigError";
  } catch (const ConfigError& e) {
    EXPECT_EQ(e.line(), 3);
    EXPECT_EQ(e.key(), "y");
    EXPECT_NE(e.file().find("frames.csv"), std::string::npos);
  }
}

TEST_F(DatasetExportTest, EurocLayoutTimestampsExtrinsicsImuAndGroundTruth) {
  testing::WriteFakeRun(run_);
  const DatasetExportSummary s = Export(DatasetFormat::kEuroc, "cam/right");
  EXPECT_EQ(s.imu, "imu");
  EXPECT_EQ(s.imu_samples, 12);
  const fs::path mav = out() / "mav0";
  for (const char* cam : {"cam0", "cam1"}) {
    const auto lines = Lines(mav / cam / "data.csv");
    ASSERT_EQ(lines.size(), 5u);
    EXPECT_EQ(lines[0], "#timestamp [ns],filename");
    int64_t previous = -1;
    for (size_t i = 1; i < lines.size(); ++i) {
      const auto f = Fields(lines[i], ',');
      ASSERT_EQ(f.size(), 2u);
      const int64_t ns = std::stoll(f[0]);
      EXPECT_EQ(f[0], std::to_string(ns));  // an integer
      EXPECT_EQ(ns, std::llround(0.05 * (i - 1) * 1e9));
      EXPECT_GT(ns, previous);
      previous = ns;
      EXPECT_EQ(f[1], f[0] + ".png");
      const cv::Mat img = cv::imread((mav / cam / "data" / f[1]).string(), cv::IMREAD_UNCHANGED);
      ASSERT_FALSE(img.empty()) << f[1];
      EXPECT_EQ(img.type(), CV_8UC1);  // greyscale as EuRoC's
    }
  }
  // cam0 sensor.yaml: T_BS = camera in the IMU (body) frame, 4x4 row-major
  const std::string yaml = ReadAll(mav / "cam0" / "sensor.yaml");
  EXPECT_NE(yaml.find("sensor_type: camera"), std::string::npos);
  EXPECT_NE(yaml.find("rate_hz: 20\n"), std::string::npos) << yaml;
  EXPECT_NE(yaml.find("resolution: [8, 6]"), std::string::npos);
  EXPECT_NE(yaml.find("camera_model: pinhole"), std::string::npos);
  EXPECT_NE(yaml.find("intrinsics: [10, 11, 4, 3]"), std::string::npos) << yaml;
  EXPECT_NE(yaml.find("distortion_model: radial-tangential"), std::string::npos);
  EXPECT_NE(yaml.find("distortion_coefficients: [0, 0, 0, 0]"), std::string::npos);
  const size_t data = yaml.find("data: [");
  ASSERT_NE(data, std::string::npos);
  std::string numbers = yaml.substr(data + 7, yaml.find(']', data) - data - 7);
  for (char& c : numbers)
    if (c == ',' || c == '\n') c = ' ';
  const auto v = Fields(numbers, ' ');
  ASSERT_EQ(v.size(), 16u);
  const Eigen::Matrix4d expected =
      (testing::FakeImuMount().inverse() * testing::FakeCameraMount()).matrix();
  for (int i = 0; i < 16; ++i) EXPECT_NEAR(std::stod(v[i]), expected(i / 4, i % 4), 1e-12) << i;
  // imu0: 7 columns, w then a
  const auto imu = Lines(mav / "imu0" / "data.csv");
  ASSERT_EQ(imu.size(), 13u);
  EXPECT_EQ(imu[0],
            "#timestamp [ns],w_RS_S_x [rad s^-1],w_RS_S_y [rad s^-1],w_RS_S_z [rad s^-1],"
            "a_RS_S_x [m s^-2],a_RS_S_y [m s^-2],a_RS_S_z [m s^-2]");
  const auto row3 = Fields(imu[4], ',');
  ASSERT_EQ(row3.size(), 7u);
  EXPECT_EQ(row3[0], "15000000");
  EXPECT_DOUBLE_EQ(std::stod(row3[2]), -0.06);  // gyro y of sample 3
  EXPECT_DOUBLE_EQ(std::stod(row3[4]), 0.3);    // accel x of sample 3
  EXPECT_NE(ReadAll(mav / "imu0" / "sensor.yaml").find("gyroscope_noise_density: 0.00024"),
            std::string::npos);
  // ground truth: 17 columns, unit quaternion (w x y z), velocity and biases
  const auto gt = Lines(mav / "state_groundtruth_estimate0" / "data.csv");
  ASSERT_EQ(gt.size(), 13u);
  EXPECT_EQ(Fields(gt[0], ',').size(), 17u);
  EXPECT_EQ(gt[0].substr(0, 22), "#timestamp, p_RS_R_x [");
  for (size_t i = 1; i < gt.size(); ++i) {
    const auto f = Fields(gt[i], ',');
    ASSERT_EQ(f.size(), 17u);
    EXPECT_EQ(std::stoll(f[0]), std::llround((i - 1) * 0.005 * 1e9));
    const Eigen::Quaterniond q(std::stod(f[4]), std::stod(f[5]), std::stod(f[6]), std::stod(f[7]));
    EXPECT_NEAR(q.norm(), 1.0, 1e-8);
    EXPECT_NEAR(2 * std::atan2(q.z(), q.w()), 0.05 * (i - 1), 1e-8);
    EXPECT_DOUBLE_EQ(std::stod(f[8]), 2.0);
    EXPECT_NEAR(std::stod(f[11]), 1e-4 * (i - 1), 1e-15);
    EXPECT_DOUBLE_EQ(std::stod(f[15]), 2e-3);
  }
}

TEST_F(DatasetExportTest, EurocRefusesACameraMovingRelativeToTheImu) {
  testing::FakeRunSpec spec;
  spec.imu_rigid_body = "robot/leg";
  testing::WriteFakeRun(run_, spec);
  try {
    Export(DatasetFormat::kEuroc);
    FAIL() << "expected a ConfigError";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("move relative to each other"), std::string::npos)
        << e.what();
  }
  EXPECT_FALSE(fs::exists(out()));
}

// a run without an IMU: EuRoC says what is missing and how to get it, and writes nothing
TEST_F(DatasetExportTest, EurocOfARunWithoutAnImuSaysWhatIsMissing) {
  testing::WriteFakeRun(run_);
  std::ofstream(run_ / "rig.json")
      << R"({"cameras": {"cam": {"body": "robot/head", "X_BS": )"
      << testing::PoseJson(testing::FakeCameraMount())
      << R"(, "rigid_body": "robot/base", "X_RS": )"
      << testing::PoseJson(testing::FakeCameraMount()) << R"(}}, "imus": {}, "lidars": {}})";
  try {
    Export(DatasetFormat::kEuroc);
    FAIL() << "expected a ConfigError";
  } catch (const ConfigError& e) {
    EXPECT_EQ(e.key(), "imus");
    EXPECT_NE(e.file().find("rig.json"), std::string::npos) << e.what();
    EXPECT_NE(e.problem().find("the run has no IMU; EuRoC needs one (imu0)"), std::string::npos)
        << e.what();
    EXPECT_NE(e.problem().find("`type: imu`"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(out()));
}

TEST_F(DatasetExportTest, EurocRefusesK3Distortion) {
  testing::FakeRunSpec spec;
  spec.k3 = 0.01;
  testing::WriteFakeRun(run_, spec);
  EXPECT_THROW(Export(DatasetFormat::kEuroc), ConfigError);
}

TEST_F(DatasetExportTest, KittiPosesCalibTimesAndImages) {
  testing::WriteFakeRun(run_);
  EXPECT_EQ(Export(DatasetFormat::kKitti, "cam/right").frames, 4);
  const fs::path seq = out() / "sequences" / "00";
  // poses: 12 numbers per line, T_0i; the first is the identity
  const auto poses = Lines(out() / "poses" / "00.txt");
  ASSERT_EQ(poses.size(), 4u);
  const Pose X_W0 = testing::FakeCameraPose(0);
  for (size_t i = 0; i < poses.size(); ++i) {
    const auto f = Fields(poses[i], ' ');
    ASSERT_EQ(f.size(), 12u);
    const Pose T = PoseFromKittiRow(f);
    const Pose expected = X_W0.inverse() * testing::FakeCameraPose(static_cast<int>(i));
    EXPECT_LT((T.matrix() - expected.matrix()).cwiseAbs().maxCoeff(), 1e-8) << i;
    if (i == 0) {
      EXPECT_TRUE(T.matrix().isIdentity(0));
    }
  }
  // times: one per frame, strictly increasing, seconds
  const auto times = Lines(seq / "times.txt");
  ASSERT_EQ(times.size(), 4u);
  for (size_t i = 0; i < times.size(); ++i) EXPECT_NEAR(std::stod(times[i]), 0.05 * i, 1e-9);
  // calib: P0..P3, Tr, 12 numbers each; P1 = K [I | (-baseline, 0, 0)]
  const auto calib = Lines(seq / "calib.txt");
  ASSERT_EQ(calib.size(), 5u);
  const char* keys[] = {"P0:", "P1:", "P2:", "P3:", "Tr:"};
  std::vector<std::vector<double>> m;
  for (int k = 0; k < 5; ++k) {
    const auto f = Fields(calib[k], ' ');
    ASSERT_EQ(f.size(), 13u);
    EXPECT_EQ(f[0], keys[k]);
    m.emplace_back();
    for (int i = 1; i < 13; ++i) m.back().push_back(std::stod(f[i]));
  }
  const std::vector<double> P0 = {10, 0, 4, 0, 0, 11, 3, 0, 0, 0, 1, 0};
  std::vector<double> P1 = P0;
  P1[3] = -10 * 0.1;
  for (int i = 0; i < 12; ++i) {
    EXPECT_NEAR(m[0][i], P0[i], 1e-12);
    EXPECT_NEAR(m[1][i], P1[i], 1e-9);
    EXPECT_NEAR(m[2][i], P0[i], 1e-12);
    EXPECT_NEAR(m[3][i], P1[i], 1e-9);
    EXPECT_EQ(m[4][i], (i == 0 || i == 5 || i == 10) ? 1.0 : 0.0);
  }
  // images renumbered from 000000: grey image_0/1, colour image_2/3 byte for byte
  for (const char* folder : {"image_0", "image_1", "image_2", "image_3"}) {
    std::set<std::string> names;
    for (const auto& e : fs::directory_iterator(seq / folder)) names.insert(e.path().filename());
    EXPECT_EQ(names,
              (std::set<std::string>{"000000.png", "000001.png", "000002.png", "000003.png"}));
  }
  EXPECT_EQ(cv::imread((seq / "image_0/000002.png").string(), cv::IMREAD_UNCHANGED).type(),
            CV_8UC1);
  EXPECT_EQ(ReadBytes(seq / "image_3/000002.png"), ReadBytes(run_ / "cam/right/rgb/000002.png"));
  // grey = OpenCV BT.601 luma of the colour pixel
  const cv::Mat grey = cv::imread((seq / "image_0/000002.png").string(), cv::IMREAD_UNCHANGED);
  const cv::Mat bgr = cv::imread((run_ / "cam/rgb/000002.png").string(), cv::IMREAD_COLOR);
  const cv::Vec3b p = bgr.at<cv::Vec3b>(4, 5);
  EXPECT_NEAR(grey.at<uint8_t>(4, 5), 0.114 * p[0] + 0.587 * p[1] + 0.299 * p[2], 0.6);
}

TEST_F(DatasetExportTest, KittiRefusesDistortionAndUnsynchronisedPairs) {
  testing::FakeRunSpec spec;
  spec.k3 = 0.01;
  testing::WriteFakeRun(run_, spec);
  EXPECT_THROW(Export(DatasetFormat::kKitti), ConfigError);
  // right camera with one frame fewer
  TempDir other;
  testing::WriteFakeRun(other.path());
  std::string csv = ReadAll(other.path() / "cam/right/frames.csv");
  csv.erase(csv.rfind('\n', csv.size() - 2) + 1);
  std::ofstream(other.path() / "cam/right/frames.csv") << csv;
  RunCamera c0 = RunFolder(other.path()).ReadCamera("cam");
  RunCamera c1 = RunFolder(other.path()).ReadCamera("cam/right");
  EXPECT_THROW(StereoExtrinsics(c0, c1), ConfigError);
  // equal times but a moving relative pose
  c1 = c0;
  c1.name = "cam/right";
  c1.frames[2].X_WO.translation().x() += 0.01;
  EXPECT_THROW(StereoExtrinsics(c0, c1), ConfigError);
}

TEST(DatasetExportOptions, ValidateOrThrow) {
  DatasetExportOptions o;
  o.out_dir = "x";
  EXPECT_NO_THROW(o.ValidateOrThrow());
  o.camera2 = "b";
  EXPECT_THROW(o.ValidateOrThrow(), ConfigError);  // TUM has one camera
  o.format = DatasetFormat::kKitti;
  EXPECT_NO_THROW(o.ValidateOrThrow());
  o.imu = "i";
  EXPECT_THROW(o.ValidateOrThrow(), ConfigError);  // IMU with EuRoC only
  o.imu = "";
  o.sequence = "7";
  EXPECT_THROW(o.ValidateOrThrow(), ConfigError);
  EXPECT_THROW(ParseDatasetFormat("rosbag"), ConfigError);
  EXPECT_EQ(ParseDatasetFormat("euroc"), DatasetFormat::kEuroc);
}

// a PID that no process has now: a child that has exited and been waited for
int64_t DeadPid() {
  const pid_t pid = fork();
  if (pid == 0) _exit(0);
  int status = 0;
  waitpid(pid, &status, 0);
  return pid;
}

// SIGKILL of an export left its "<out>.export-tmp-*" folder (or bag file) for ever: the next
// export into the same parent removes those whose process is gone, never one a live export holds
TEST_F(DatasetExportTest, AnExportRemovesTempsOfKilledExportsAndNoneALiveOneHolds) {
  testing::WriteFakeRun(run_);
  const int64_t dead = DeadPid();
  ASSERT_NE(kill(static_cast<pid_t>(dead), 0), 0);
  const fs::path parent = tmp_.path();
  const fs::path stale_dir = parent / fmt::format("old.export-tmp-{}-0123456789ab", dead);
  const fs::path stale_replay = parent / fmt::format("old.replay-tmp-{}-0123456789ac", dead);
  const fs::path stale_bag = parent / fmt::format("x.bag.export-tmp-{}-aaaaaaaaaaaa", dead);
  const fs::path live_dir = parent / fmt::format("live.export-tmp-{}-0123456789ab", getpid());
  const fs::path held_dir = parent / fmt::format("held.export-tmp-{}-bbbbbbbbbbbb", dead);
  const fs::path not_temp = parent / "notes.export-tmp-mine";
  for (const fs::path& d : {stale_dir, stale_replay, live_dir, held_dir, not_temp}) {
    fs::create_directories(d / "rgb");
    std::ofstream(d / "rgb" / "0.png") << "x";
  }
  std::ofstream(stale_bag) << "half a bag";
  // a live export's lock (its PID reused, or in another PID namespace): never removed
  const int held = open(held_dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  ASSERT_GE(held, 0);
  ASSERT_EQ(flock(held, LOCK_EX | LOCK_NB), 0);

  Export(DatasetFormat::kTum);
  EXPECT_TRUE(fs::is_regular_file(out() / "rgb.txt"));
  EXPECT_FALSE(fs::exists(stale_dir));
  EXPECT_FALSE(fs::exists(stale_replay));
  EXPECT_FALSE(fs::exists(stale_bag));
  EXPECT_TRUE(fs::exists(live_dir / "rgb" / "0.png"));
  EXPECT_TRUE(fs::exists(held_dir / "rgb" / "0.png"));
  EXPECT_TRUE(fs::exists(not_temp / "rgb" / "0.png"));
  close(held);
  // released: removed by the next call
  EXPECT_EQ(RemoveStaleExportTemps(out()), std::vector<fs::path>{held_dir});
  EXPECT_TRUE(fs::exists(live_dir));
}

TEST(DatasetExportTemp, TempNamesCarryThePidAndTheCreatorHoldsALock) {
  TempDir tmp;
  UniqueFd lock;
  const fs::path d = MakeSiblingTempFolder(tmp.path() / "out", ".export-tmp", &lock);
  EXPECT_EQ(ExportTempOwner(d.filename().string()), getpid()) << d;
  EXPECT_EQ(d.filename().string().rfind(fmt::format("out.export-tmp-{}-", getpid()), 0), 0u);
  const int other = open(d.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  EXPECT_NE(flock(other, LOCK_EX | LOCK_NB), 0);  // held by `lock`
  close(other);
  UniqueFd file_lock;
  const fs::path f = MakeSiblingTempFile(tmp.path() / "a.bag", ".export-tmp", &file_lock);
  EXPECT_EQ(ExportTempOwner(f.filename().string()), getpid()) << f;
  EXPECT_TRUE(fs::is_regular_file(f));
  EXPECT_EQ(ExportTempOwner("a.export-tmp-12-0123456789abc"), 0);  // 13 hex digits
  EXPECT_EQ(ExportTempOwner("a.export-tmp-0123456789ab"), 0);      // no PID (older names)
  EXPECT_EQ(ExportTempOwner("a.export-tmp--0123456789ab"), 0);
  EXPECT_EQ(ExportTempOwner("a.replay-tmp-42-0123456789ab"), 42);
}

}  // namespace
}  // namespace penumbra
