#pragma once
// the files of the world-file sensors (sinks/sensor_sink.h runs the sensors; these write the
// records the sensor models return):
//
//   <out>/lidar/<name>/scan_<k>.pcd   binary PCD v0.7 (output/pcd_writer.h)
//   <out>/lidar/<name>/index.csv      scan,capture_time_sec,delivery_time_sec,file,points,
//                                     medium_returns,particle_returns
//   <out>/imu/<name>.csv              sample,capture_time_sec,delivery_time_sec,
//                                     accel_{x,y,z}_m_s2,gyro_{x,y,z}_rad_s
//   <out>/imu/<name>_truth.csv        sample,capture_time_sec, the true state of the IMU frame S
//                                     at the sample: x_m,y_m,z_m,qw,qx,qy,qz (X_WS),
//                                     vx_m_s,vy_m_s,vz_m_s (velocity of S's origin, world axes),
//                                     bg{x,y,z}_rad_s, ba{x,y,z}_m_s2 (the noise model's gyro
//                                     and accelerometer biases added to this sample, S axes)
//   <out>/sensors/<name>.csv          sample,capture_time_sec,delivery_time_sec, one column per
//                                     MuJoCo sensor value
//   <out>/ground_truth/<name>.csv     sample,time_sec, per body <body>_{x,y,z}_m,
//                                     _q{w,x,y,z}, _w{x,y,z}_rad_s, _v{x,y,z}_m_s (X_WB, V_WB)
//   <out>/ground_truth/<name>_contacts.csv  sample,time_sec,geom1,geom2,body1,body2,
//                                     p{x,y,z}_m,n{x,y,z},distance_m,f{n,t1,t2}_N
//
// times are printed with 9 decimals ({:.9f}), values with 9 significant digits ({:.9g}). CSV
// files only ever hold whole rows (core/output_file.h). one writer is used from one thread.

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "penumbra/core/output_file.h"
#include "penumbra/scene/world_snapshot.h"
#include "penumbra/sensors/imu_model.h"
#include "penumbra/sensors/lidar_scanner.h"
#include "penumbra/sensors/sensor_schedule.h"

namespace penumbra {

/// the scans of one LiDAR.
class LidarScanWriter {
 public:
  LidarScanWriter() = default;
  /// creates <out>/lidar/<name>/ and its index.csv header.
  /// @throws Error naming the path if it cannot be created.
  LidarScanWriter(const std::filesystem::path& out, const std::string& name);
  /// writes scan_<firing.index>.pcd and its index.csv row; returns the PCD file's bytes.
  /// @throws Error naming the file that could not be written.
  std::string Write(const SensorFiring& firing, const LidarScan& scan);
  /// writes the buffered rows and closes index.csv. @throws Error as Write.
  void Close() { index_.Close(); }

 private:
  std::filesystem::path dir_;
  LineFile index_;
};

/// the samples of one IMU.
class ImuCsvWriter {
 public:
  ImuCsvWriter() = default;
  /// creates <out>/imu/<name>.csv with its header. @throws Error as LidarScanWriter.
  ImuCsvWriter(const std::filesystem::path& out, const std::string& name);
  /// appends the row of sample `firing.index`; returns the row (with '\n').
  /// @throws Error if the write fails.
  std::string Write(const SensorFiring& firing, const ImuSample& sample);
  void Close() { csv_.Close(); }

 private:
  LineFile csv_;
};

/// the true state of one IMU at its samples (what the noisy samples of ImuCsvWriter measure).
struct ImuTruth {
  Pose X_WS = Pose::Identity();         ///< IMU frame in the world
  Eigen::Vector3d v_WS{0, 0, 0};        ///< velocity of S's origin in the world, world axes, m/s
  Eigen::Vector3d gyro_bias{0, 0, 0};   ///< gyro bias in this sample, S axes, rad/s
  Eigen::Vector3d accel_bias{0, 0, 0};  ///< accelerometer bias in this sample, S axes, m/s^2
};

/// the true state of one IMU at its samples.
class ImuTruthCsvWriter {
 public:
  ImuTruthCsvWriter() = default;
  /// creates <out>/imu/<name>_truth.csv with its header. @throws Error as LidarScanWriter.
  ImuTruthCsvWriter(const std::filesystem::path& out, const std::string& name);
  /// appends the row of sample `firing.index`. @throws Error if the write fails.
  void Write(const SensorFiring& firing, const ImuTruth& truth);
  void Close() { csv_.Close(); }

 private:
  LineFile csv_;
};

/// the samples of one set of MuJoCo sensors.
class MujocoSensorCsvWriter {
 public:
  MujocoSensorCsvWriter() = default;
  /// creates <out>/sensors/<name>.csv with the header naming `columns` (with units).
  /// @throws Error as LidarScanWriter.
  MujocoSensorCsvWriter(const std::filesystem::path& out, const std::string& name,
                        const std::vector<std::string>& columns);
  /// appends the row of sample `firing.index` (one value per column); returns the row (with
  /// '\n'). @throws Error if the write fails.
  std::string Write(const SensorFiring& firing, const std::vector<double>& values);
  void Close() { csv_.Close(); }

 private:
  LineFile csv_;
};

/// body poses, twists and (optionally) contacts read from snapshots.
class GroundTruthCsvWriter {
 public:
  GroundTruthCsvWriter() = default;
  /// creates <out>/ground_truth/<name>.csv (columns for `bodies`, indices into X_WB, named
  /// `body_names`) and, with `contacts`, <name>_contacts.csv. @throws Error as LidarScanWriter.
  GroundTruthCsvWriter(const std::filesystem::path& out, const std::string& name,
                       const std::vector<int>& bodies, const std::vector<std::string>& body_names,
                       bool contacts);
  /// appends the rows of sample `sample` at `snapshot` (kFull). @throws Error if a write fails.
  void Write(int64_t sample, const WorldSnapshot& snapshot);
  /// closes both files (both are closed even if the first fails). @throws Error of the first.
  void Close();

 private:
  std::vector<int> bodies_;
  bool contacts_ = false;
  LineFile csv_, contacts_csv_;
};

}  // namespace penumbra
