#include "penumbra/sensors/lidar_pattern.h"

#include <algorithm>
#include <cmath>
#include <complex>
#include <cstdint>

#include "penumbra/core/error.h"
#include "penumbra/scene/scene_limits.h"

namespace penumbra {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kDeg = kPi / 180.0;

// columns per scan for `beams_per_second` at `rate_hz` (a preset's default), checked against
// kMaxLidarBeamsPerScan before it is rounded to an int.
int DefaultColumns(const std::string& preset, double beams_per_second, int rings, double rate_hz) {
  const double cols = std::round(beams_per_second / rate_hz);
  if (!(cols * rings <= kMaxLidarBeamsPerScan))
    throw Error("lidar preset '" + preset + "': rate_hz " + std::to_string(rate_hz) + " gives " +
                std::to_string(cols) + " columns x " + std::to_string(rings) +
                " rings per scan; expected at most " + std::to_string(kMaxLidarBeamsPerScan) +
                " beams per scan (raise rate_hz or set columns)");
  return static_cast<int>(cols);
}

void CheckBeams(const std::string& name, double columns, int rings) {
  if (!(columns * rings <= kMaxLidarBeamsPerScan))
    throw Error("lidar '" + name + "': " + std::to_string(static_cast<int64_t>(columns)) +
                " columns x " + std::to_string(rings) + " rings is " +
                std::to_string(static_cast<int64_t>(columns * rings)) +
                " beams per scan; expected at most " + std::to_string(kMaxLidarBeamsPerScan));
}

std::vector<double> Uniform(int n, double lo_deg, double hi_deg) {
  std::vector<double> v(n);
  for (int i = 0; i < n; ++i) v[i] = n == 1 ? lo_deg : lo_deg + (hi_deg - lo_deg) * i / (n - 1);
  return v;
}

LidarPattern Rosette(int points, double rate_hz) {
  LidarPattern p;
  p.name = "livox_mid40";
  p.spinning = false;
  p.rings = 1;
  p.columns = points;
  p.rate_hz = rate_hz;
  p.min_range_m = 1.0;
  p.max_range_m = 260;
  p.beam_divergence_rad = 0.28 * kDeg;
  // two Risley prisms, each deflecting by delta, turning at w1 and -w2 (rad/s); the
  // incommensurate ratio makes the pattern non-repetitive
  const double delta = 9.6 * kDeg;
  const double w1 = 2 * kPi * 121.0, w2 = 2 * kPi * 79.3;
  const double period = 1.0 / rate_hz;
  p.beams.reserve(points);
  for (int i = 0; i < points; ++i) {
    const double t = period * i / points;
    const std::complex<double> th = delta * (std::exp(std::complex<double>(0, w1 * t)) +
                                             std::exp(std::complex<double>(0, -w2 * t)));
    LidarBeam b;
    b.azimuth_rad = static_cast<float>(th.real());
    b.elevation_rad = static_cast<float>(th.imag());
    b.time_sec = static_cast<float>(t);
    b.ring = 0;
    b.column = i;
    p.beams.push_back(b);
  }
  return p;
}

LidarPattern Raster(double rate_hz) {
  LidarPattern p;
  p.name = "solid_state_raster";
  p.spinning = false;
  const int cols = 600, rows = 125;  // 120 x 25 deg at 0.2 deg
  p.rings = rows;
  p.columns = rows;  // one firing group per row: rows are swept top to bottom
  p.rate_hz = rate_hz;
  p.min_range_m = 0.5;
  p.max_range_m = 150;
  p.beam_divergence_rad = 0.1 * kDeg;
  const double period = 1.0 / rate_hz;
  p.beams.reserve(static_cast<size_t>(rows) * cols);
  for (int r = 0; r < rows; ++r) {
    const int ring = rows - 1 - r;  // top row first; ring 0 = lowest
    const double el = (-12.5 + 25.0 * ring / (rows - 1)) * kDeg;
    const float t = static_cast<float>(period * r / rows);
    for (int c = 0; c < cols; ++c) {
      LidarBeam b;
      b.azimuth_rad = static_cast<float>((60.0 - 120.0 * c / (cols - 1)) * kDeg);
      b.elevation_rad = static_cast<float>(el);
      b.time_sec = t;
      b.ring = ring;
      b.column = r;
      p.beams.push_back(b);
    }
  }
  return p;
}

}  // namespace

void LidarPattern::Direction(int i, float* x, float* y, float* z) const {
  const LidarBeam& b = beams[i];
  const float ce = std::cos(b.elevation_rad);
  *x = ce * std::cos(b.azimuth_rad);
  *y = ce * std::sin(b.azimuth_rad);
  *z = std::sin(b.elevation_rad);
}

const std::vector<std::string>& LidarPresetNames() {
  static const std::vector<std::string> names = {
      "velodyne_vlp16", "ouster_os1_64", "ouster_os1_128", "livox_mid40", "solid_state_raster"};
  return names;
}

LidarPattern MakeSpinningPattern(const std::string& name, std::vector<double> elevations_deg,
                                 int columns, double rate_hz) {
  if (elevations_deg.empty()) throw Error("lidar '" + name + "': no rings");
  if (columns < 1) throw Error("lidar '" + name + "': columns must be >= 1");
  if (!(std::isfinite(rate_hz) && rate_hz > 0))
    throw Error("lidar '" + name + "': rate_hz must be > 0");
  CheckBeams(name, columns, static_cast<int>(elevations_deg.size()));
  std::sort(elevations_deg.begin(), elevations_deg.end());
  LidarPattern p;
  p.name = name;
  p.spinning = true;
  p.rings = static_cast<int>(elevations_deg.size());
  p.columns = columns;
  p.rate_hz = rate_hz;
  p.ring_elevation_deg = elevations_deg;
  const double period = 1.0 / rate_hz;
  p.beams.reserve(static_cast<size_t>(columns) * p.rings);
  for (int c = 0; c < columns; ++c) {
    // clockwise seen from above: azimuth decreases with time, wrapped to (-pi, pi]
    double az = -2 * kPi * c / columns;
    if (az <= -kPi) az += 2 * kPi;
    const float t = static_cast<float>(period * c / columns);
    for (int r = 0; r < p.rings; ++r) {
      LidarBeam b;
      b.azimuth_rad = static_cast<float>(az);
      b.elevation_rad = static_cast<float>(elevations_deg[r] * kDeg);
      b.time_sec = t;
      b.ring = r;
      b.column = c;
      p.beams.push_back(b);
    }
  }
  return p;
}

LidarPattern MakeLidarPattern(const std::string& preset, const LidarPatternOptions& o) {
  if (o.columns < 0) throw Error("lidar preset '" + preset + "': columns must be >= 1");
  if (!(std::isfinite(o.rate_hz) && o.rate_hz >= 0))
    throw Error("lidar preset '" + preset + "': rate_hz must be > 0");
  LidarPattern p;
  if (preset == "velodyne_vlp16") {
    const double rate = o.rate_hz > 0 ? o.rate_hz : 10.0;
    // 0.2 deg at 10 Hz; the azimuth step scales with the rate (VLP-16: 0.1-0.4 deg at 5-20 Hz)
    const int cols = o.columns > 0 ? o.columns : DefaultColumns(preset, 18000.0, 16, rate);
    p = MakeSpinningPattern(preset, Uniform(16, -15, 15), cols, rate);
    p.min_range_m = 0.5;
    p.max_range_m = 100;
    p.beam_divergence_rad = 0.003;  // 3 mrad horizontal (datasheet beam divergence)
  } else if (preset == "ouster_os1_64" || preset == "ouster_os1_128") {
    const int rings = preset == "ouster_os1_64" ? 64 : 128;
    const double rate = o.rate_hz > 0 ? o.rate_hz : 10.0;
    const int cols = o.columns > 0 ? o.columns : 1024;
    if (cols != 512 && cols != 1024 && cols != 2048)
      throw Error("lidar preset '" + preset + "': columns " + std::to_string(cols) +
                  " is not an OS1 mode; expected 512, 1024 or 2048");
    if (rate != 10.0 && rate != 20.0)
      throw Error("lidar preset '" + preset + "': rate_hz " + std::to_string(rate) +
                  " is not an OS1 mode; expected 10 or 20");
    if (cols == 2048 && rate == 20.0)
      throw Error("lidar preset '" + preset + "': 2048 columns run only at 10 Hz");
    p = MakeSpinningPattern(preset, Uniform(rings, -22.5, 22.5), cols, rate);
    p.min_range_m = 0.3;
    p.max_range_m = 120;
    p.beam_divergence_rad = 0.0016;  // 0.09 deg FWHM (OS1 datasheet)
  } else if (preset == "livox_mid40") {
    const double rate = o.rate_hz > 0 ? o.rate_hz : 10.0;
    const int pts = o.columns > 0 ? o.columns : DefaultColumns(preset, 100000.0, 1, rate);
    CheckBeams(preset, pts, 1);
    p = Rosette(pts, rate);
  } else if (preset == "solid_state_raster") {
    if (o.columns > 0)
      throw Error("lidar preset 'solid_state_raster': columns cannot be changed (600 x 125)");
    p = Raster(o.rate_hz > 0 ? o.rate_hz : 10.0);
  } else {
    std::string names;
    for (const std::string& n : LidarPresetNames()) names += (names.empty() ? "" : ", ") + n;
    throw Error("unknown lidar preset '" + preset + "'; expected one of: " + names);
  }
  if (o.max_range_m > 0) p.max_range_m = o.max_range_m;
  if (o.min_range_m >= 0) p.min_range_m = o.min_range_m;
  if (!(p.min_range_m < p.max_range_m))
    throw Error("lidar preset '" + preset + "': min_range_m must be below max_range_m");
  return p;
}

}  // namespace penumbra
