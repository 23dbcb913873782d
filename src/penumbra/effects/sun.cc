#include "penumbra/effects/sun.h"

#include <algorithm>
#include <cmath>

namespace penumbra {

namespace {

constexpr double kSunPi = 3.14159265358979323846;
double Rad(double d) { return d * kSunPi / 180.0; }
double Deg(double r) { return r * 180.0 / kSunPi; }

// NOAA's refraction correction (degrees) for an apparent-elevation estimate e (degrees).
double Refraction(double e) {
  if (e > 85.0) return 0.0;
  const double te = std::tan(Rad(e));
  double arcsec = 0;
  if (e > 5.0) {
    arcsec = 58.1 / te - 0.07 / std::pow(te, 3) + 0.000086 / std::pow(te, 5);
  } else if (e > -0.575) {
    arcsec = 1735.0 + e * (-518.2 + e * (103.4 + e * (-12.79 + e * 0.711)));
  } else {
    arcsec = -20.774 / te;
  }
  return arcsec / 3600.0;
}

}  // namespace

double JulianDay(int year, int month, int day, double hour_utc) {
  int y = year, m = month;
  if (m <= 2) {
    y -= 1;
    m += 12;
  }
  const int a = y / 100;
  const int b = 2 - a + a / 4;
  return std::floor(365.25 * (y + 4716)) + std::floor(30.6001 * (m + 1)) + day + b - 1524.5 +
         hour_utc / 24.0;
}

SunPosition ComputeSunPosition(double jd, double lat_deg, double lon_deg) {
  const double T = (jd - 2451545.0) / 36525.0;  // Julian centuries since J2000.0
  const double L0 = std::fmod(280.46646 + T * (36000.76983 + T * 0.0003032), 360.0);
  const double M = 357.52911 + T * (35999.05029 - 0.0001537 * T);
  const double e = 0.016708634 - T * (0.000042037 + 0.0000001267 * T);
  const double C = std::sin(Rad(M)) * (1.914602 - T * (0.004817 + 0.000014 * T)) +
                   std::sin(Rad(2 * M)) * (0.019993 - 0.000101 * T) +
                   std::sin(Rad(3 * M)) * 0.000289;
  const double true_long = L0 + C;
  const double omega = 125.04 - 1934.136 * T;
  const double app_long = true_long - 0.00569 - 0.00478 * std::sin(Rad(omega));
  const double eps0 =
      23.0 + (26.0 + (21.448 - T * (46.815 + T * (0.00059 - T * 0.001813))) / 60.0) / 60.0;
  const double eps = eps0 + 0.00256 * std::cos(Rad(omega));
  const double decl = Deg(std::asin(std::sin(Rad(eps)) * std::sin(Rad(app_long))));
  const double y = std::pow(std::tan(Rad(eps / 2)), 2);
  const double eot =
      4.0 * Deg(y * std::sin(2 * Rad(L0)) - 2 * e * std::sin(Rad(M)) +
                4 * e * y * std::sin(Rad(M)) * std::cos(2 * Rad(L0)) -
                0.5 * y * y * std::sin(4 * Rad(L0)) - 1.25 * e * e * std::sin(2 * Rad(M)));

  // minutes past midnight UTC of this Julian day
  const double day_frac = jd + 0.5 - std::floor(jd + 0.5);
  const double tst = std::fmod(day_frac * 1440.0 + eot + 4.0 * lon_deg + 1440.0 * 2, 1440.0);
  double ha = tst / 4.0 - 180.0;
  if (ha < -180) ha += 360;

  const double cos_z =
      std::clamp(std::sin(Rad(lat_deg)) * std::sin(Rad(decl)) +
                     std::cos(Rad(lat_deg)) * std::cos(Rad(decl)) * std::cos(Rad(ha)),
                 -1.0, 1.0);
  const double zenith = Deg(std::acos(cos_z));
  const double sin_z = std::sin(Rad(zenith));
  double az = 0;
  const double denom = std::cos(Rad(lat_deg)) * sin_z;
  if (std::abs(denom) > 1e-12) {
    const double c =
        std::clamp((std::sin(Rad(lat_deg)) * cos_z - std::sin(Rad(decl))) / denom, -1.0, 1.0);
    const double a = Deg(std::acos(c));
    az = ha > 0 ? std::fmod(a + 180.0, 360.0) : std::fmod(540.0 - a, 360.0);
  } else {
    az = lat_deg > 0 ? 180.0 : 0.0;
  }

  SunPosition p;
  p.geometric_elevation_deg = 90.0 - zenith;
  p.elevation_deg = p.geometric_elevation_deg + Refraction(p.geometric_elevation_deg);
  p.azimuth_deg = az;
  p.declination_deg = decl;
  p.equation_of_time_min = eot;
  return p;
}

Eigen::Vector3d SunDirectionEnu(const SunPosition& p) {
  const double el = Rad(p.elevation_deg), az = Rad(p.azimuth_deg);
  return {std::sin(az) * std::cos(el), std::cos(az) * std::cos(el), std::sin(el)};
}

double TwilightSkyScale(double h) {
  if (h >= 0) return 1.0;
  // (elevation deg, log10 of illuminance / 400 lx)
  static const double kH[4] = {0.0, -6.0, -12.0, -18.0};
  static const double kLog[4] = {0.0, std::log10(3.4 / 400.0), std::log10(0.008 / 400.0),
                                 std::log10(0.001 / 400.0)};
  if (h <= kH[3]) return std::pow(10.0, kLog[3]);
  int i = 0;
  while (h < kH[i + 1]) ++i;
  const double f = (kH[i] - h) / (kH[i] - kH[i + 1]);
  return std::pow(10.0, kLog[i] + f * (kLog[i + 1] - kLog[i]));
}

double DirectSunAttenuation(double elevation_deg) {
  if (elevation_deg <= 0) return 0.0;
  const double h_rad = Rad(elevation_deg);
  const double air_mass =
      1.0 / (std::sin(h_rad) + 0.50572 * std::pow(elevation_deg + 6.07995, -1.6364));
  return std::pow(0.7, std::pow(air_mass, 0.678)) / 0.7;
}

}  // namespace penumbra
