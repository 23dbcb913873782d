#include "penumbra/world/camera_config_reader.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <set>

#include "penumbra/core/text_match.h"
#include "penumbra/render/camera/camera_distortion.h"
#include "penumbra/scene/scene_limits.h"
#include "penumbra/sensors/camera_profile.h"

namespace penumbra {
namespace {

// "cameras[2] ('front')" for messages.
std::string Who(const CameraConfig& c) { return "camera '" + c.name + "': "; }

double NonNegative(const ParamReader& r, const CameraConfig& c, const std::string& unit) {
  const double v = r.Double();
  if (!(v >= 0))
    r.Fail(Who(c) + "got " + FormatNumber(v) + "; expected a number >= 0 (" + unit + ")");
  return v;
}

double Positive(const ParamReader& r, const CameraConfig& c, const std::string& unit) {
  const double v = r.Double();
  if (!(v > 0))
    r.Fail(Who(c) + "got " + FormatNumber(v) + "; expected a number > 0 (" + unit + ")");
  return v;
}

// a number in [lo, hi] (lo_open: (lo, hi]); 1e308 or 1e-300 where a camera needs a sane value
double Within(const ParamReader& r, const CameraConfig& c, double lo, double hi, bool lo_open,
              const std::string& unit) {
  const double v = r.Double();
  if (!((lo_open ? v > lo : v >= lo) && v <= hi))
    r.Fail(Who(c) + "got " + FormatNumber(v) + "; expected " + (lo_open ? "(" : "[") +
           FormatNumber(lo) + ", " + FormatNumber(hi) + "] (" + unit + ")");
  return v;
}

int IntIn(const ParamReader& r, const CameraConfig& c, int lo, int hi) {
  const int v = r.Int();
  if (v < lo || v > hi)
    r.Fail(Who(c) + "got " + std::to_string(v) + "; expected an integer in [" + std::to_string(lo) +
           ", " + std::to_string(hi) + "]");
  return v;
}

// the camera's intrinsics as scene assembly will build them (for the fold check).
CameraIntrinsics IntrinsicsOf(const CameraConfig& c) {
  CameraIntrinsics k = c.intrinsics
                           ? *c.intrinsics
                           : CameraIntrinsics::FromFovy(c.width, c.height, c.fovy_deg.value_or(60));
  k.width = c.width;
  k.height = c.height;
  k.k1 = c.k1, k.k2 = c.k2, k.p1 = c.p1, k.p2 = c.p2, k.k3 = c.k3;
  return k;
}

}  // namespace

const std::vector<std::string_view>& CameraSensorKeys() {
  static const std::vector<std::string_view> keys = {"profile",
                                                     "distortion",
                                                     "exposure_time_sec",
                                                     "motion_blur_samples",
                                                     "rolling_shutter_line_time_sec",
                                                     "auto_exposure_time_constant_sec",
                                                     "noise",
                                                     "optics",
                                                     "auto_exposure",
                                                     "jpeg_quality",
                                                     "lens_droplets",
                                                     "white_balance",
                                                     "depth_noise",
                                                     "stereo"};
  return keys;
}

CameraProfile ReadCameraProfile(const ParamReader& r, const std::string& who) {
  const std::string name = r.String();
  const std::optional<CameraProfile> p = FindCameraProfile(name);
  if (!p)
    r.Fail(who + "unknown camera profile '" + name + "'; expected one of: " + CameraProfileNames());
  return *p;
}

void ReadCameraSensorKeys(const ParamReader& r, CameraConfig* c) {
  CameraSensorConfig& s = c->sensor;
  // the profile first: the keys below override its values
  if (const auto found = r.Find("profile"))
    s = CameraProfileConfig(ReadCameraProfile(*found, Who(*c)));
  if (r.Has("distortion")) {
    const ParamReader d = r.Child("distortion");
    d.ExpectMap({"k1", "k2", "p1", "p2", "k3"});
    double* field[] = {&c->k1, &c->k2, &c->p1, &c->p2, &c->k3};
    const char* name[] = {"k1", "k2", "p1", "p2", "k3"};
    // radial k1 k2 k3, tangential p1 p2 (scene/scene_limits.h)
    const double bound[] = {kMaxRadialDistortion, kMaxRadialDistortion, kMaxTangentialDistortion,
                            kMaxTangentialDistortion, kMaxRadialDistortion};
    for (int i = 0; i < 5; ++i)
      if (const auto found = d.Find(name[i]))
        *field[i] = Within(*found, *c, -bound[i], bound[i], false, "distortion coefficient");
    // an MJCF camera override without fovy_deg / intrinsics keeps the MJCF fovy, known only
    // after compilation: scene assembly checks it then (world/camera_specs.h)
    const bool optics_known = c->fovy_deg || c->intrinsics;
    const CameraIntrinsics k = IntrinsicsOf(*c);
    if (optics_known && k.fx > 0 && k.fy > 0 && k.width > 0 && k.height > 0) {
      if (auto problem = FindDistortionProblem(k))
        d.Fail(Who(*c) + *problem +
               "; expected k1 k2 p1 p2 k3 that map the image one-to-one "
               "(smaller coefficients or a narrower field of view)");
    }
  }
  if (r.Has("exposure_time_sec"))
    s.exposure_time_sec = Within(r.Child("exposure_time_sec"), *c, 0, 60, false, "seconds");
  if (r.Has("motion_blur_samples"))
    s.motion_blur_samples = IntIn(r.Child("motion_blur_samples"), *c, 1, 64);
  if (r.Has("rolling_shutter_line_time_sec")) {
    s.rolling_shutter_line_time_sec =
        Within(r.Child("rolling_shutter_line_time_sec"), *c, 0, 0.01, false, "seconds per row");
    s.rolling_shutter_readout_sec = 0;  // the explicit line time replaces the profile's readout
  }
  if (r.Has("auto_exposure_time_constant_sec"))
    s.auto_exposure_time_constant_sec =
        Within(r.Child("auto_exposure_time_constant_sec"), *c, 0, 3600, false, "seconds");
  if (r.Has("noise")) {
    const ParamReader n = r.Child("noise");
    n.ExpectMap({"enabled", "full_well_e", "read_noise_e", "iso", "base_iso", "adc_bits",
                 "dark_current_e_per_s", "dsnu_e", "prnu"});
    s.noise.enabled = n.Has("enabled") ? n.Child("enabled").Bool() : true;
    if (n.Has("full_well_e"))
      s.noise.full_well_e = Within(n.Child("full_well_e"), *c, 1, 1e9, false, "electrons");
    if (n.Has("read_noise_e"))
      s.noise.read_noise_e = Within(n.Child("read_noise_e"), *c, 0, 1e6, false, "electrons");
    if (const auto found = n.Find("iso")) s.noise.iso = Within(*found, *c, 0, 1e7, true, "ISO");
    if (const auto found = n.Find("base_iso"))
      s.noise.base_iso = Within(*found, *c, 0, 1e7, true, "ISO");
    if (const auto found = n.Find("adc_bits")) s.noise.adc_bits = IntIn(*found, *c, 1, 16);
    if (const auto found = n.Find("dark_current_e_per_s"))
      s.noise.dark_current_e_per_s = Within(*found, *c, 0, 1e9, false, "electrons per second");
    if (const auto found = n.Find("dsnu_e"))
      s.noise.dsnu_e = Within(*found, *c, 0, 1e6, false, "electrons");
    if (const auto found = n.Find("prnu"))
      s.noise.prnu = Within(*found, *c, 0, 0.5, false, "fraction of the signal");
  }
  if (r.Has("optics")) {
    const ParamReader o = r.Child("optics");
    o.ExpectMap({"vignetting_exponent", "psf_sigma_px", "lateral_ca_px", "reference_width"});
    if (const auto found = o.Find("vignetting_exponent"))
      s.optics.vignetting_exponent = Within(*found, *c, 0, 8, false, "cos^n exponent");
    if (const auto found = o.Find("psf_sigma_px"))
      s.optics.psf_sigma_px = Within(*found, *c, 0, 20, false, "px");
    if (const auto found = o.Find("lateral_ca_px"))
      s.optics.lateral_ca_px = Within(*found, *c, 0, 20, false, "px");
    if (const auto found = o.Find("reference_width"))
      s.optics.reference_width = IntIn(*found, *c, 0, 100000);
  }
  if (r.Has("auto_exposure")) {
    const ParamReader a = r.Child("auto_exposure");
    a.ExpectMap({"enabled", "f_number", "min_exposure_time_sec", "max_exposure_time_sec",
                 "max_gain", "saturated_fraction", "max_highlight_reduction_ev",
                 "motion_blur_step_sec"});
    AutoExposureConfig& ae = s.auto_exposure;
    ae.enabled = a.Has("enabled") ? a.Child("enabled").Bool() : true;
    if (const auto found = a.Find("f_number")) ae.f_number = Within(*found, *c, 0, 1000, true, "");
    if (const auto found = a.Find("min_exposure_time_sec"))
      ae.min_exposure_time_sec = Within(*found, *c, 0, 60, true, "seconds");
    if (const auto found = a.Find("max_exposure_time_sec"))
      ae.max_exposure_time_sec = Within(*found, *c, 0, 60, true, "seconds");
    if (ae.max_exposure_time_sec < ae.min_exposure_time_sec)
      a.Fail(Who(*c) + "expected max_exposure_time_sec >= min_exposure_time_sec");
    if (const auto found = a.Find("max_gain")) ae.max_gain = Within(*found, *c, 1, 1e6, false, "x");
    if (const auto found = a.Find("saturated_fraction"))
      ae.saturated_fraction = Within(*found, *c, 0, 1, false, "fraction of the pixels");
    if (const auto found = a.Find("max_highlight_reduction_ev"))
      ae.max_highlight_reduction_ev = Within(*found, *c, 0, 10, false, "EV");
    if (const auto found = a.Find("motion_blur_step_sec"))
      ae.motion_blur_step_sec = Within(*found, *c, 0, 60, false, "seconds");
  }
  if (const auto found = r.Find("jpeg_quality")) s.jpeg_quality = IntIn(*found, *c, 0, 100);
  if (r.Has("lens_droplets")) {
    const ParamReader l = r.Child("lens_droplets");
    l.ExpectMap({"enabled", "count"});
    if (const auto found = l.Find("enabled")) s.lens_droplets = found->Bool();
    if (const auto found = l.Find("count")) s.lens_droplet_count = IntIn(*found, *c, 0, 1000);
  }
  if (r.Has("white_balance")) {
    const ParamReader w = r.Child("white_balance");
    const std::string v = w.String();
    if (v == "auto") {
      s.white_balance.mode = WhiteBalance::Mode::kAuto;
    } else if (v == "daylight") {
      s.white_balance.mode = WhiteBalance::Mode::kDaylight;
    } else if (v == "none") {
      s.white_balance.mode = WhiteBalance::Mode::kNone;
    } else {
      char* end = nullptr;
      const double k = std::strtod(v.c_str(), &end);
      if (v.empty() || end != v.c_str() + v.size() || !(k >= WhiteBalance::kMinKelvin) ||
          !(k <= WhiteBalance::kMaxKelvin))
        w.Fail(Who(*c) + "white_balance '" + v +
               "' is not known; expected auto, daylight, none or a colour temperature in "
               "[1667, 25000] K");
      s.white_balance.mode = WhiteBalance::Mode::kKelvin;
      s.white_balance.kelvin = k;
    }
  }
  if (r.Has("depth_noise")) {
    const ParamReader d = r.Child("depth_noise");
    d.ExpectMap({"preset", "min_range_m", "max_range_m"});
    std::vector<std::string_view> presets(std::begin(kDepthNoisePresets),
                                          std::end(kDepthNoisePresets));
    const ParamReader p = d.Child("preset");
    s.depth_noise.preset = p.String();
    if (std::find(presets.begin(), presets.end(), s.depth_noise.preset) == presets.end())
      p.Fail(Who(*c) + "unknown depth noise preset '" + s.depth_noise.preset +
             "'; expected one of: " + JoinNames(presets));
    if (d.Has("min_range_m"))
      s.depth_noise.min_range_m = NonNegative(d.Child("min_range_m"), *c, "m");
    if (const auto found = d.Find("max_range_m"))
      s.depth_noise.max_range_m = Positive(*found, *c, "m");
    if (s.depth_noise.min_range_m && s.depth_noise.max_range_m &&
        !(*s.depth_noise.max_range_m > *s.depth_noise.min_range_m))
      d.Child("max_range_m").Fail(Who(*c) + "expected max_range_m > min_range_m");
  }
  if (r.Has("stereo")) {
    const ParamReader st = r.Child("stereo");
    if (c->is_mjcf_override)
      st.Fail(Who(*c) +
              "MJCF cameras cannot be made stereo pairs; expected a world-file camera "
              "(under cameras:) for a stereo pair");
    st.ExpectMap({"baseline_m"});
    s.stereo_baseline_m = Within(st.Child("baseline_m"), *c, 0, 100, true, "m");
  }
}

std::vector<SemanticClassConfig> ReadSemanticClasses(const ParamReader& r) {
  std::vector<SemanticClassConfig> out;
  std::set<std::string> names;
  std::set<int> ids;
  for (const ParamReader& e : r.List()) {
    e.ExpectMap({"name", "id", "bodies", "geoms", "materials"});
    SemanticClassConfig c;
    c.name = e.Child("name").String();
    if (auto problem = NameLengthProblem(c.name)) e.Child("name").Fail(*problem);
    const ParamReader id = e.Child("id");
    c.id = id.Int();
    if (c.id < 1 || c.id > 65535)
      id.Fail("class '" + c.name + "': got " + std::to_string(c.id) +
              "; expected an integer in [1, 65535] (0 = unlabelled)");
    if (!names.insert(c.name).second)
      e.Child("name").Fail("class '" + c.name + "' is listed twice; expected unique names");
    if (!ids.insert(c.id).second)
      id.Fail("class id " + std::to_string(c.id) + " is used twice; expected unique ids");
    auto patterns = [&](const char* key, std::vector<std::string>* v) {
      if (!e.Has(key)) return;
      for (const ParamReader& p : e.Child(key).List()) v->push_back(p.String());
    };
    patterns("bodies", &c.bodies);
    patterns("geoms", &c.geoms);
    patterns("materials", &c.materials);
    if (c.bodies.empty() && c.geoms.empty() && c.materials.empty())
      e.Fail("class '" + c.name + "' has no patterns; expected some of bodies, geoms, materials");
    out.push_back(std::move(c));
  }
  return out;
}

}  // namespace penumbra
