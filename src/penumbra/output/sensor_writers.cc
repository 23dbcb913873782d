#include "penumbra/output/sensor_writers.h"

#include <fmt/format.h>

#include <Eigen/Geometry>
#include <exception>
#include <iterator>

#include "penumbra/output/pcd_writer.h"
#include "penumbra/sensors/sensor_types.h"

namespace penumbra {
namespace {

namespace fs = std::filesystem;

// the run folders of the sensor types (sensors/sensor_types.h)
const fs::path kLidarFolder(LidarSensorParams::kOutputFolder);
const fs::path kImuFolder(ImuSensorParams::kOutputFolder);
const fs::path kMujocoFolder(MujocoSensorParams::kOutputFolder);
const fs::path kGroundTruthFolder(GroundTruthSensorParams::kOutputFolder);

// a streaming CSV under the output folder `out` (whole rows only, core/output_file.h)
LineFile OpenCsv(const fs::path& out, const fs::path& rel) {
  CreateOutputFolder(out, rel.parent_path());
  return LineFile(out / rel);
}

}  // namespace

LidarScanWriter::LidarScanWriter(const fs::path& out, const std::string& name)
    : dir_(out / kLidarFolder / name), index_(OpenCsv(out, kLidarFolder / name / "index.csv")) {
  index_.Append(
      "scan,capture_time_sec,delivery_time_sec,file,points,medium_returns,"
      "particle_returns\n");
}

std::string LidarScanWriter::Write(const SensorFiring& f, const LidarScan& scan) {
  const std::string file = fmt::format("scan_{:06d}.pcd", f.index);
  std::string pcd = EncodePcd(scan.points);
  WriteFileAtomic(dir_ / file, pcd);
  index_.Append(fmt::format("{},{:.9f},{:.9f},{},{},{},{}\n", f.index, f.capture_time_sec,
                            f.delivery_time_sec, file, scan.points.size(), scan.medium_returns,
                            scan.particle_returns));
  return pcd;
}

ImuCsvWriter::ImuCsvWriter(const fs::path& out, const std::string& name)
    : csv_(OpenCsv(out, kImuFolder / (name + ".csv"))) {
  csv_.Append(
      "sample,capture_time_sec,delivery_time_sec,accel_x_m_s2,accel_y_m_s2,"
      "accel_z_m_s2,gyro_x_rad_s,gyro_y_rad_s,gyro_z_rad_s\n");
}

std::string ImuCsvWriter::Write(const SensorFiring& f, const ImuSample& o) {
  std::string row =
      fmt::format("{},{:.9f},{:.9f},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g}\n", f.index,
                  f.capture_time_sec, f.delivery_time_sec, o.accel_m_s2.x(), o.accel_m_s2.y(),
                  o.accel_m_s2.z(), o.gyro_rad_s.x(), o.gyro_rad_s.y(), o.gyro_rad_s.z());
  csv_.Append(row);
  return row;
}

ImuTruthCsvWriter::ImuTruthCsvWriter(const fs::path& out, const std::string& name)
    : csv_(OpenCsv(out, kImuFolder / (name + "_truth.csv"))) {
  csv_.Append(
      "sample,capture_time_sec,x_m,y_m,z_m,qw,qx,qy,qz,vx_m_s,vy_m_s,vz_m_s,bgx_rad_s,"
      "bgy_rad_s,bgz_rad_s,bax_m_s2,bay_m_s2,baz_m_s2\n");
}

void ImuTruthCsvWriter::Write(const SensorFiring& f, const ImuTruth& t) {
  const Eigen::Vector3d& p = t.X_WS.translation();
  Eigen::Quaterniond q(t.X_WS.linear());
  if (q.w() < 0) q.coeffs() = -q.coeffs();
  csv_.Append(fmt::format(
      "{},{:.9f},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g},"
      "{:.9g},{:.9g},{:.9g},{:.9g},{:.9g}\n",
      f.index, f.capture_time_sec, p.x(), p.y(), p.z(), q.w(), q.x(), q.y(), q.z(), t.v_WS.x(),
      t.v_WS.y(), t.v_WS.z(), t.gyro_bias.x(), t.gyro_bias.y(), t.gyro_bias.z(), t.accel_bias.x(),
      t.accel_bias.y(), t.accel_bias.z()));
}

MujocoSensorCsvWriter::MujocoSensorCsvWriter(const fs::path& out, const std::string& name,
                                             const std::vector<std::string>& columns)
    : csv_(OpenCsv(out, kMujocoFolder / (name + ".csv"))) {
  std::string header = "sample,capture_time_sec,delivery_time_sec";
  for (const std::string& col : columns) header += "," + col;
  csv_.Append(header + "\n");
}

std::string MujocoSensorCsvWriter::Write(const SensorFiring& f, const std::vector<double>& values) {
  std::string row =
      fmt::format("{},{:.9f},{:.9f}", f.index, f.capture_time_sec, f.delivery_time_sec);
  for (double v : values) fmt::format_to(std::back_inserter(row), ",{:.9g}", v);
  row += '\n';
  csv_.Append(row);
  return row;
}

GroundTruthCsvWriter::GroundTruthCsvWriter(const fs::path& out, const std::string& name,
                                           const std::vector<int>& bodies,
                                           const std::vector<std::string>& body_names,
                                           bool contacts)
    : bodies_(bodies),
      contacts_(contacts),
      csv_(OpenCsv(out, kGroundTruthFolder / (name + ".csv"))) {
  std::string header = "sample,time_sec";
  for (int b : bodies_) {
    const std::string& n = body_names.at(b);
    for (const char* k : {"x_m", "y_m", "z_m", "qw", "qx", "qy", "qz", "wx_rad_s", "wy_rad_s",
                          "wz_rad_s", "vx_m_s", "vy_m_s", "vz_m_s"})
      header += "," + n + "_" + k;
  }
  csv_.Append(header + "\n");
  if (contacts_) {
    contacts_csv_ = OpenCsv(out, kGroundTruthFolder / (name + "_contacts.csv"));
    contacts_csv_.Append(
        "sample,time_sec,geom1,geom2,body1,body2,px_m,py_m,pz_m,nx,ny,nz,"
        "distance_m,fn_N,ft1_N,ft2_N\n");
  }
}

void GroundTruthCsvWriter::Write(int64_t sample, const WorldSnapshot& snap) {
  std::string row = fmt::format("{},{:.9f}", sample, snap.time_sec);
  for (int b : bodies_) {
    const Pose& X = snap.X_WB.at(b);
    const Eigen::Quaterniond q(X.linear());
    const Eigen::Matrix<double, 6, 1> V =
        b < static_cast<int>(snap.V_WB.size()) ? snap.V_WB[b] : Eigen::Matrix<double, 6, 1>::Zero();
    fmt::format_to(std::back_inserter(row),
                   ",{:.9g},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g},"
                   "{:.9g},{:.9g},{:.9g}",
                   X.translation().x(), X.translation().y(), X.translation().z(), q.w(), q.x(),
                   q.y(), q.z(), V[0], V[1], V[2], V[3], V[4], V[5]);
  }
  row += '\n';
  csv_.Append(row);
  if (!contacts_) return;
  for (const WorldSnapshot::Contact& c : snap.contacts)
    contacts_csv_.Append(
        fmt::format("{},{:.9f},{},{},{},{},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g},"
                    "{:.9g},{:.9g}\n",
                    sample, snap.time_sec, c.geom1, c.geom2, c.body1, c.body2, c.p_W.x(), c.p_W.y(),
                    c.p_W.z(), c.normal_W.x(), c.normal_W.y(), c.normal_W.z(), c.distance_m,
                    c.force_N.x(), c.force_N.y(), c.force_N.z()));
}

void GroundTruthCsvWriter::Close() {
  std::exception_ptr first;
  for (LineFile* f : {&csv_, &contacts_csv_}) {
    try {
      f->Close();
    } catch (...) {
      if (!first) first = std::current_exception();
    }
  }
  if (first) std::rethrow_exception(first);
}

}  // namespace penumbra
