#include "penumbra/output/sensor_writers.h"

#include <gtest/gtest.h>

#include "common/temp_dir.h"
#include "penumbra/output/pcd_writer.h"

namespace penumbra {
namespace {

namespace fs = std::filesystem;
using testing::ReadAll;
using testing::TempDir;

SensorFiring Firing(int64_t k, double t, double latency) {
  SensorFiring f;
  f.index = k;
  f.capture_time_sec = t;
  f.delivery_time_sec = t + latency;
  return f;
}

TEST(SensorWritersTest, ImuRowsHaveTheDocumentedColumnsAndPrecision) {
  TempDir dir;
  ImuCsvWriter w(dir.path(), "imu0");
  ImuSample s;
  s.accel_m_s2 = {0.1, -9.80665, 1.0 / 3.0};
  s.gyro_rad_s = {0, 2e-7, -1};
  w.Write(Firing(3, 0.015, 0.002), s);
  w.Close();
  EXPECT_EQ(ReadAll(dir.path() / "imu" / "imu0.csv"),
            "sample,capture_time_sec,delivery_time_sec,accel_x_m_s2,accel_y_m_s2,accel_z_m_s2,"
            "gyro_x_rad_s,gyro_y_rad_s,gyro_z_rad_s\n"
            "3,0.015000000,0.017000000,0.1,-9.80665,0.333333333,0,2e-07,-1\n");
}

TEST(SensorWritersTest, MujocoSensorRowsFollowTheColumns) {
  TempDir dir;
  MujocoSensorCsvWriter w(dir.path(), "joints", {"a_rad", "b_m"});
  w.Write(Firing(0, 0, 0), {1.5, -2});
  w.Close();
  EXPECT_EQ(ReadAll(dir.path() / "sensors" / "joints.csv"),
            "sample,capture_time_sec,delivery_time_sec,a_rad,b_m\n"
            "0,0.000000000,0.000000000,1.5,-2\n");
}

TEST(SensorWritersTest, LidarScansGoToPcdFilesListedInTheIndex) {
  TempDir dir;
  LidarScanWriter w(dir.path(), "top");
  LidarScan scan;
  LidarPoint p;
  p.x = 1;
  p.y = 2;
  p.z = 3;
  p.intensity = 0.5f;
  p.ring = 7;
  p.time = 0.01f;
  scan.points = {p, p};
  scan.medium_returns = 1;
  w.Write(Firing(12, 1.2, 0.1), scan);
  w.Close();
  EXPECT_EQ(ReadAll(dir.path() / "lidar" / "top" / "index.csv"),
            "scan,capture_time_sec,delivery_time_sec,file,points,medium_returns,"
            "particle_returns\n"
            "12,1.200000000,1.300000000,scan_000012.pcd,2,1,0\n");
  const std::vector<LidarPoint> back =
      ReadPcd((dir.path() / "lidar" / "top" / "scan_000012.pcd").string());
  ASSERT_EQ(back.size(), 2u);
  EXPECT_EQ(back[1].ring, 7);
  EXPECT_EQ(back[1].z, 3.0f);
}

TEST(SensorWritersTest, GroundTruthRowsAndContacts) {
  TempDir dir;
  GroundTruthCsvWriter w(dir.path(), "gt", {1}, {"world", "box"}, true);
  WorldSnapshot s;
  s.time_sec = 0.5;
  s.X_WB = {Pose::Identity(), Pose::Identity()};
  s.X_WB[1].translation() = Eigen::Vector3d(1, 2, 3);
  WorldSnapshot::Contact c;
  c.geom1 = 0;
  c.geom2 = 4;
  c.body1 = 0;
  c.body2 = 1;
  c.force_N = {10, 0, 0};
  s.contacts = {c};
  w.Write(2, s);
  w.Close();
  const std::string rows = ReadAll(dir.path() / "ground_truth" / "gt.csv");
  EXPECT_EQ(rows.substr(rows.find('\n') + 1), "2,0.500000000,1,2,3,1,0,0,0,0,0,0,0,0,0\n");
  EXPECT_EQ(rows.substr(0, rows.find(',', 20)), "sample,time_sec,box_x_m");
  const std::string contacts = ReadAll(dir.path() / "ground_truth" / "gt_contacts.csv");
  EXPECT_EQ(contacts.substr(contacts.find('\n') + 1),
            "2,0.500000000,0,4,0,1,0,0,0,0,0,1,0,10,0,0\n");
}

}  // namespace
}  // namespace penumbra
