#include "penumbra/sensors/types/lidar.h"

#include "penumbra/scene/scene_limits.h"
#include "penumbra/sensors/lidar_pattern.h"

namespace penumbra {

std::vector<std::string_view> LidarSensorParams::Keys() {
  return {"preset",
          "columns",
          "min_range_m",
          "max_range_m",
          "beam_divergence_mrad",
          "reference_reflectivity",
          "intensity_range_normalized",
          "media",
          "noise"};
}

void LidarSensorParams::Read(const SensorParamReader& r) {
  std::vector<std::string_view> presets;
  for (const std::string& n : LidarPresetNames()) presets.push_back(n);
  preset = r.Enum("preset", presets);
  if (r.Has("columns")) {
    const int v = r.Integer("columns");
    if (v < 1 || v > kMaxLidarBeamsPerScan)
      r.Fail("columns", "got " + std::to_string(v) + "; expected an integer in [1, " +
                            std::to_string(kMaxLidarBeamsPerScan) +
                            "] (rings x columns is at most " +
                            std::to_string(kMaxLidarBeamsPerScan) + " beams per scan)");
    columns = v;
  }
  // ranges within the world's extent (scene/scene_limits.h); a divergence of at most 1 rad
  if (r.Has("min_range_m")) min_range_m = r.NonNegative("min_range_m", "m", kMaxPositionM);
  if (r.Has("max_range_m")) max_range_m = r.NonNegative("max_range_m", "m", kMaxPositionM);
  if (r.Has("beam_divergence_mrad"))
    beam_divergence_mrad = r.NonNegative("beam_divergence_mrad", "mrad", 1000);
  if (r.Has("reference_reflectivity")) {
    const double v = r.Double("reference_reflectivity");
    if (!(v > 0 && v <= 1))
      r.Fail("reference_reflectivity", "got " + SensorNumber(v) + "; expected (0, 1]");
    reference_reflectivity = v;
  }
  if (r.Has("intensity_range_normalized"))
    intensity_range_normalized = r.Boolean("intensity_range_normalized");
  if (r.Has("media")) media = r.Boolean("media");
  if (r.Has("noise")) {
    const auto n = r.Map(
        "noise", {"range_stddev_m", "dropout_probability", "min_intensity", "receiver_noise"});
    if (n->Has("range_stddev_m")) range_stddev_m = n->Noise("range_stddev_m");
    if (n->Has("dropout_probability")) {
      dropout_probability = n->Noise("dropout_probability");
      if (dropout_probability > 1)
        n->Fail("dropout_probability",
                "got " + SensorNumber(dropout_probability) + "; expected a probability in [0, 1]");
    }
    if (n->Has("min_intensity")) min_intensity = n->Noise("min_intensity");
    if (n->Has("receiver_noise")) receiver_noise = n->Noise("receiver_noise");
  }
}

LidarPatternOptions LidarSensorParams::PatternOptions(double rate_hz) const {
  LidarPatternOptions po;
  po.columns = columns;
  po.rate_hz = rate_hz;
  po.max_range_m = max_range_m;
  po.min_range_m = min_range_m;
  return po;
}

LidarConfig LidarSensorParams::MakeConfig(double rate_hz) const {
  LidarConfig lc;
  lc.pattern = MakeLidarPattern(preset, PatternOptions(rate_hz));
  if (beam_divergence_mrad) lc.pattern.beam_divergence_rad = *beam_divergence_mrad * 1e-3;
  lc.range_noise_stddev_m = range_stddev_m;
  lc.dropout_probability = dropout_probability;
  lc.min_intensity = min_intensity;
  lc.receiver_noise = receiver_noise;
  lc.reference_reflectivity = reference_reflectivity;
  lc.intensity_range_normalized = intensity_range_normalized;
  lc.media = media;
  return lc;
}

}  // namespace penumbra
