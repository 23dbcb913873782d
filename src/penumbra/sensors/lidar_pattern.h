#pragma once
// LiDAR scan patterns: which beams one scan fires, in which direction and when.
//
// sensor frame S (REP-103): x forward, y left, z up. azimuth is measured from +x towards +y
// (counter-clockwise seen from above), elevation from the x-y plane towards +z. a beam's unit
// direction in S is (cos el cos az, cos el sin az, sin el).
//
// spinning sensors fire one column of all rings at once per azimuth step and turn clockwise
// seen from above (Velodyne and Ouster both do), so column c is at azimuth -360 c / columns
// deg and at time c / (columns rate_hz) after the scan start. real Velodyne units fire their
// lasers one after another within a 55.3 us firing cycle (VLP-16 user manual, ch. 9); that
// sub-column stagger (< 0.06 % of a scan) is not modelled.
//
// presets (uniform vertical spacing where the datasheet gives a uniform beam configuration):
//  - velodyne_vlp16: 16 rings, -15..+15 deg in 2 deg steps, 0.2 deg azimuth at 10 Hz
//    (1800 columns), 100 m range (Velodyne VLP-16 datasheet 63-9229 Rev-C).
//  - ouster_os1_64 / ouster_os1_128: 64 / 128 rings uniform over 45 deg (+-22.5 deg; the
//    OS1 Rev 7 datasheet's "uniform" beam configuration, 0.7 / 0.35 deg spacing), 1024
//    columns at 10 Hz by default (512, 1024 or 2048 allowed; 2048 only at 10 Hz and 1024 at
//    up to 20 Hz, as the OS1 lidar modes), 120 m range (datasheet: 120 m at 80 %
//    reflectivity with > 90 % detection probability, rev 6; approximate).
//  - livox_mid40: non-repetitive rosette from two Risley prisms turning in opposite
//    directions (Livox Mid-40 datasheet: 38.4 deg circular field of view, 100 000 points/s,
//    260 m at 80 %), 10 000 points per 0.1 s scan; deflection
//    theta(t) = delta (e^{i w1 t} + e^{-i w2 t}) with delta = 9.6 deg (so |theta| <= 19.2 deg).
//  - solid_state_raster: rectangular raster 120 x 25 deg (horizontal x vertical), 0.2 x 0.2
//    deg, rows scanned top to bottom within the frame at 10 Hz, 150 m (a generic MEMS
//    automotive sensor class; not a particular datasheet).

#include <string>
#include <vector>

namespace penumbra {

/// one beam of a scan.
struct LidarBeam {
  float azimuth_rad = 0;    ///< from +x towards +y, sensor frame
  float elevation_rad = 0;  ///< from the x-y plane towards +z
  float time_sec = 0;       ///< firing time since the scan start, in [0, scan period)
  int ring = 0;             ///< laser (row) index: 0 = lowest elevation for spinning sensors
  int column = 0;           ///< firing group (all beams of a column share time_sec)
};

/// the beams of one scan and the sensor limits.
struct LidarPattern {
  std::string name;
  bool spinning = true;
  int rings = 0;                       ///< lasers (rows); spinning: beams per column
  int columns = 0;                     ///< firing groups per scan
  double rate_hz = 10;                 ///< scans per second
  double min_range_m = 0.3;            ///< returns closer than this are dropped
  double max_range_m = 100;            ///< rays are traced up to this range
  double beam_divergence_rad = 0.003;  ///< full-angle divergence (particle coverage)
  /// elevation of each ring (spinning), ascending, deg; empty for non-spinning patterns.
  std::vector<double> ring_elevation_deg;
  /// every beam, grouped by column in firing order (column-major).
  std::vector<LidarBeam> beams;

  /// unit direction of beam `i` in the sensor frame.
  void Direction(int i, float* x, float* y, float* z) const;
};

/// names accepted by MakeLidarPattern.
const std::vector<std::string>& LidarPresetNames();

/// options that change a preset.
struct LidarPatternOptions {
  int columns = 0;          ///< 0 = the preset's (spinning: 512, 1024, 2048 for Ouster; any >= 1)
  double rate_hz = 0;       ///< 0 = the preset's
  double max_range_m = 0;   ///< 0 = the preset's
  double min_range_m = -1;  ///< < 0 = the preset's
};

/// builds a preset pattern.
/// @throws Error for an unknown preset (listing the names) or options out of range
///         (columns < 1, rate <= 0, Ouster column counts other than 512/1024/2048, more than
///         kMaxLidarBeamsPerScan beams per scan (scene/scene_limits.h), also when a preset's
///         default column count, beams per second / rate_hz, would exceed it).
LidarPattern MakeLidarPattern(const std::string& preset, const LidarPatternOptions& options = {});

/// a spinning pattern from a table of ring elevations (deg, any order; rings are numbered
/// in ascending elevation), `columns` per revolution at `rate_hz`.
/// @throws Error for no rings, columns < 1, rate_hz <= 0 or more than kMaxLidarBeamsPerScan
///         beams.
LidarPattern MakeSpinningPattern(const std::string& name, std::vector<double> elevations_deg,
                                 int columns, double rate_hz);

}  // namespace penumbra
