#include "penumbra/dataset/run_folder.h"

#include <fmt/format.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "penumbra/core/error.h"
#include "penumbra/dataset/run_file.h"

namespace penumbra {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::ordered_json;

// `relative` under the run folder `dir`, parsed
Json ReadJson(const fs::path& dir, const fs::path& relative) {
  const std::string text = ReadRunFile(dir, relative);
  try {
    return Json::parse(text);
  } catch (const Json::exception& e) {
    throw ConfigError((dir / relative).string(), 0, "", std::string("not valid JSON: ") + e.what());
  }
}

// a camera or IMU name from the run's JSON must name files inside the run folder
void CheckSensorName(const std::string& name, const fs::path& file, const std::string& key) {
  if (!IsPlainRelativePath(fs::path(name)))
    throw ConfigError(file.string(), 0, key,
                      "name '" + name +
                          "' is not a path inside the run folder (absolute, empty or with a "
                          "'.' or '..' component); expected a sensor name");
}

std::vector<std::string> Split(const std::string& line) {
  std::vector<std::string> out;
  size_t start = 0;
  while (true) {
    const size_t comma = line.find(',', start);
    out.push_back(
        line.substr(start, comma == std::string::npos ? std::string::npos : comma - start));
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  return out;
}

// a CSV file with a fixed header: rows of numbers as text, with their line numbers
struct Csv {
  fs::path path;
  std::vector<std::string> columns;
  std::vector<std::vector<std::string>> rows;
  std::vector<int> lines;

  double Number(size_t row, size_t col) const {
    const std::string& s = rows[row][col];
    double v = 0;
    const auto r = std::from_chars(s.data(), s.data() + s.size(), v);
    if (r.ec != std::errc() || r.ptr != s.data() + s.size() || !std::isfinite(v))
      throw ConfigError(path.string(), lines[row], columns[col],
                        "'" + s + "' is not a finite number");
    return v;
  }
  int64_t Integer(size_t row, size_t col) const {
    const std::string& s = rows[row][col];
    int64_t v = 0;
    const auto r = std::from_chars(s.data(), s.data() + s.size(), v);
    if (r.ec != std::errc() || r.ptr != s.data() + s.size())
      throw ConfigError(path.string(), lines[row], columns[col], "'" + s + "' is not an integer");
    return v;
  }
};

Csv ReadCsv(const fs::path& dir, const fs::path& relative, const std::string& header) {
  const fs::path path = dir / relative;
  std::istringstream in(ReadRunFile(dir, relative));
  Csv csv;
  csv.path = path;
  csv.columns = Split(header);
  std::string line;
  if (!std::getline(in, line) || line != header)
    throw ConfigError(path.string(), 1, "", "header '" + line + "'; expected '" + header + "'");
  int n = 1;
  while (std::getline(in, line)) {
    ++n;
    if (line.empty()) continue;
    std::vector<std::string> cells = Split(line);
    if (cells.size() != csv.columns.size())
      throw ConfigError(
          path.string(), n, "",
          fmt::format("{} columns; expected {} ({})", cells.size(), csv.columns.size(), header));
    csv.rows.push_back(std::move(cells));
    csv.lines.push_back(n);
  }
  return csv;
}

Pose PoseFromCsv(const Csv& csv, size_t row, size_t first) {
  Eigen::Vector3d p;
  for (int i = 0; i < 3; ++i) p[i] = csv.Number(row, first + i);
  Eigen::Quaterniond q(csv.Number(row, first + 3), csv.Number(row, first + 4),
                       csv.Number(row, first + 5), csv.Number(row, first + 6));
  if (std::abs(q.norm() - 1) > 1e-6)
    throw ConfigError(csv.path.string(), csv.lines[row], csv.columns[first + 3],
                      fmt::format("quaternion of norm {}; expected a unit quaternion", q.norm()));
  Pose X = Pose::Identity();
  X.linear() = q.normalized().toRotationMatrix();
  X.translation() = p;
  return X;
}

Pose PoseFromJson(const Json& j, const fs::path& file, const std::string& key) {
  try {
    const auto xyz = j.at("xyz").get<std::vector<double>>();
    const auto q = j.at("qwxyz").get<std::vector<double>>();
    if (xyz.size() != 3 || q.size() != 4) throw Error("wrong sizes");
    Pose X = Pose::Identity();
    X.linear() = Eigen::Quaterniond(q[0], q[1], q[2], q[3]).normalized().toRotationMatrix();
    X.translation() = Eigen::Vector3d(xyz[0], xyz[1], xyz[2]);
    return X;
  } catch (const std::exception&) {
    throw ConfigError(file.string(), 0, key,
                      "expected {\"xyz\": [x, y, z], \"qwxyz\": [w, x, y, z]}");
  }
}

RunMount MountFromJson(const Json& j, const fs::path& file, const std::string& key) {
  RunMount m;
  try {
    m.body = j.at("body").get<std::string>();
    m.rigid_body = j.at("rigid_body").get<std::string>();
  } catch (const std::exception&) {
    throw ConfigError(file.string(), 0, key, "expected \"body\" and \"rigid_body\" names");
  }
  m.X_BS = PoseFromJson(j.at("X_BS"), file, key + ".X_BS");
  m.X_RS = PoseFromJson(j.at("X_RS"), file, key + ".X_RS");
  return m;
}

std::string Joined(const std::vector<std::string>& names) {
  std::string s;
  for (const std::string& n : names) s += (s.empty() ? "" : ", ") + n;
  return s.empty() ? "none" : s;
}

}  // namespace

fs::path RunCamera::ImagePath(const std::string& kind, int64_t index) const {
  return folder / kind / fmt::format("{:06d}.png", index);
}

fs::path RunCamera::RelativeImagePath(const std::string& kind, int64_t index) const {
  return fs::path(name) / kind / fmt::format("{:06d}.png", index);
}

double RunCamera::MeanRateHz() const {
  if (frames.size() < 2) return 0;
  return static_cast<double>(frames.size() - 1) /
         (frames.back().time_sec - frames.front().time_sec);
}

int64_t SecondsToNs(double time_sec) { return std::llround(time_sec * 1e9); }

RunFolder::RunFolder(fs::path dir) : dir_(std::move(dir)) {
  std::error_code ec;
  if (!fs::is_directory(dir_, ec))
    throw ConfigError(dir_.string(), 0, "",
                      "not a folder; expected the output folder of `penumbra run`");
  if (StatRunEntry(dir_, "camera_info.json") == RunEntry::kMissing &&
      StatRunEntry(dir_, "rig.json") == RunEntry::kMissing)
    throw ConfigError(dir_.string(), 0, "",
                      "has neither camera_info.json nor rig.json; expected the output folder of "
                      "`penumbra run`");
}

std::vector<std::string> RunFolder::CameraNames() const {
  std::vector<std::string> names;
  if (StatRunEntry(dir_, "camera_info.json") == RunEntry::kMissing) return names;
  const Json j = ReadJson(dir_, "camera_info.json");
  for (auto it = j.begin(); it != j.end(); ++it) names.push_back(it.key());
  return names;
}

std::vector<std::string> RunFolder::ImuNames() const {
  std::vector<std::string> names;
  if (StatRunEntry(dir_, "rig.json") == RunEntry::kMissing) return names;
  const Json j = ReadJson(dir_, "rig.json");
  if (j.contains("imus"))
    for (auto it = j["imus"].begin(); it != j["imus"].end(); ++it) names.push_back(it.key());
  return names;
}

RunCamera RunFolder::ReadCamera(const std::string& name) const {
  const std::vector<std::string> names = CameraNames();
  if (std::find(names.begin(), names.end(), name) == names.end())
    throw ConfigError("", 0, "--camera",
                      "the run has no camera '" + name + "'; expected one of: " + Joined(names));
  const fs::path info_path = dir_ / "camera_info.json";
  CheckSensorName(name, info_path, name);
  const Json info = ReadJson(dir_, "camera_info.json")[name];
  RunCamera cam;
  cam.name = name;
  cam.run_dir = dir_;
  cam.folder = dir_ / fs::path(name);
  try {
    cam.width = info.at("width").get<int>();
    cam.height = info.at("height").get<int>();
    const auto K = info.at("K").get<std::vector<double>>();
    const auto D = info.at("D").get<std::vector<double>>();
    if (K.size() != 9 || D.size() != 5) throw Error("sizes");
    cam.fx = K[0];
    cam.cx = K[2];
    cam.fy = K[4];
    cam.cy = K[5];
    for (int i = 0; i < 5; ++i) cam.distortion[i] = D[i];
  } catch (const std::exception&) {
    throw ConfigError(info_path.string(), 0, name,
                      "expected width, height, K (9 numbers) and D (5 numbers)");
  }
  // the images are checked against this size before they are decoded (PNG limits: 2^31 - 1)
  if (cam.width < 1 || cam.width > 65535 || cam.height < 1 || cam.height > 65535)
    throw ConfigError(
        info_path.string(), 0, name + ".width",
        fmt::format("{} x {} pixels; expected 1 .. 65535 each", cam.width, cam.height));
  const Csv csv = ReadCsv(dir_, fs::path(name) / "frames.csv", "frame,time_sec,x,y,z,qw,qx,qy,qz");
  for (size_t r = 0; r < csv.rows.size(); ++r) {
    RunFrame f;
    f.index = csv.Integer(r, 0);
    f.time_sec = csv.Number(r, 1);
    f.X_WO = PoseFromCsv(csv, r, 2);
    if (!cam.frames.empty() &&
        (f.index <= cam.frames.back().index || f.time_sec <= cam.frames.back().time_sec))
      throw ConfigError(csv.path.string(), csv.lines[r], "frame",
                        "frame index and time not after the previous row's; expected strictly "
                        "increasing rows");
    cam.frames.push_back(f);
  }
  cam.has_rgb = StatRunEntry(dir_, fs::path(name) / "rgb") == RunEntry::kFolder;
  cam.has_depth = StatRunEntry(dir_, fs::path(name) / "depth") == RunEntry::kFolder;
  return cam;
}

std::optional<RunMount> RunFolder::CameraMount(const std::string& name) const {
  if (StatRunEntry(dir_, "rig.json") == RunEntry::kMissing) return std::nullopt;
  const Json rig = ReadJson(dir_, "rig.json");
  if (!rig.contains("cameras") || !rig["cameras"].contains(name)) return std::nullopt;
  return MountFromJson(rig["cameras"][name], dir_ / "rig.json", "cameras." + name);
}

RunImu RunFolder::ReadImu(const std::string& name) const {
  const std::vector<std::string> names = ImuNames();
  if (std::find(names.begin(), names.end(), name) == names.end())
    throw ConfigError(
        "", 0, "--imu",
        "the run has no IMU '" + name + "' in rig.json; expected one of: " + Joined(names));
  const fs::path rig_path = dir_ / "rig.json";
  CheckSensorName(name, rig_path, "imus." + name);
  const Json j = ReadJson(dir_, "rig.json")["imus"][name];
  RunImu imu;
  imu.name = name;
  imu.mount = MountFromJson(j, rig_path, "imus." + name);
  try {
    imu.rate_hz = j.at("rate_hz").get<double>();
    imu.gyro_noise_density = j.at("gyroscope_noise_density").get<double>();
    imu.gyro_random_walk = j.at("gyroscope_random_walk").get<double>();
    imu.accel_noise_density = j.at("accelerometer_noise_density").get<double>();
    imu.accel_random_walk = j.at("accelerometer_random_walk").get<double>();
  } catch (const std::exception&) {
    throw ConfigError(rig_path.string(), 0, "imus." + name,
                      "expected rate_hz and the four noise parameters");
  }
  const fs::path dir = "imu";
  const Csv s = ReadCsv(dir_, dir / (name + ".csv"),
                        "sample,capture_time_sec,delivery_time_sec,accel_x_m_s2,accel_y_m_s2,"
                        "accel_z_m_s2,gyro_x_rad_s,gyro_y_rad_s,gyro_z_rad_s");
  for (size_t r = 0; r < s.rows.size(); ++r) {
    RunImuSample m;
    m.index = s.Integer(r, 0);
    m.time_sec = s.Number(r, 1);
    for (int i = 0; i < 3; ++i) {
      m.accel_m_s2[i] = s.Number(r, 3 + i);
      m.gyro_rad_s[i] = s.Number(r, 6 + i);
    }
    if (!imu.samples.empty() && m.time_sec <= imu.samples.back().time_sec)
      throw ConfigError(s.path.string(), s.lines[r], "capture_time_sec",
                        "not after the previous row's; expected strictly increasing times");
    imu.samples.push_back(m);
  }
  const Csv t = ReadCsv(dir_, dir / (name + "_truth.csv"),
                        "sample,capture_time_sec,x_m,y_m,z_m,qw,qx,qy,qz,vx_m_s,vy_m_s,vz_m_s,"
                        "bgx_rad_s,bgy_rad_s,bgz_rad_s,bax_m_s2,bay_m_s2,baz_m_s2");
  for (size_t r = 0; r < t.rows.size(); ++r) {
    RunImuTruth m;
    m.index = t.Integer(r, 0);
    m.time_sec = t.Number(r, 1);
    m.X_WS = PoseFromCsv(t, r, 2);
    for (int i = 0; i < 3; ++i) {
      m.v_WS[i] = t.Number(r, 9 + i);
      m.gyro_bias[i] = t.Number(r, 12 + i);
      m.accel_bias[i] = t.Number(r, 15 + i);
    }
    if (r >= imu.samples.size() || imu.samples[r].index != m.index ||
        imu.samples[r].time_sec != m.time_sec)
      throw ConfigError(t.path.string(), t.lines[r], "sample",
                        fmt::format("sample {} at {} s has no matching row in {}.csv; expected "
                                    "the same samples in both files",
                                    m.index, m.time_sec, name));
    imu.truth.push_back(m);
  }
  if (imu.truth.size() != imu.samples.size())
    throw ConfigError(t.path.string(), 0, "",
                      fmt::format("{} rows; expected {} (as {}.csv)", imu.truth.size(),
                                  imu.samples.size(), name));
  return imu;
}

}  // namespace penumbra
