#pragma once
// position of the sun and the sky level at twilight, for the `sun` effect.
//
// solar position: the NOAA Global Monitoring Laboratory solar calculator equations
// (https://gml.noaa.gov/grad/solcalc/calcdetails.html), which follow Meeus, "Astronomical
// Algorithms", Willmann-Bell 1991; stated accuracy ~0.0167 deg for years 1800-2100, with
// NOAA's atmospheric refraction correction for the apparent elevation.
//
// twilight: the sky luminance scale below the horizon is interpolated log-linearly in the
// sun's geometric elevation through typical horizontal illuminances of a clear sky:
// 400 lx at sunset (0 deg), 3.4 lx at the end of civil twilight (-6 deg), 0.008 lx at the
// end of nautical twilight (-12 deg) (values tabulated in Seidelmann (ed.), "Explanatory
// Supplement to the Astronomical Almanac", 1992) and 0.001 lx (clear moonless night,
// starlight and airglow) from -18 deg down; scale = E(h) / 400 lx, 1 above the horizon.

#include <Eigen/Core>

namespace penumbra {

/// where the sun is, as seen from a place on Earth.
struct SunPosition {
  double elevation_deg = 0;            ///< apparent (refraction-corrected) elevation
  double geometric_elevation_deg = 0;  ///< without refraction
  double azimuth_deg = 0;              ///< clockwise from north (90 = east)
  double declination_deg = 0;
  double equation_of_time_min = 0;
};

/// Julian day of a UTC calendar date and time (Meeus ch. 7, Gregorian calendar).
double JulianDay(int year, int month, int day, double hour_utc);

/// sun position at a Julian day for latitude (north +) and longitude (east +), degrees.
SunPosition ComputeSunPosition(double julian_day, double latitude_deg, double longitude_deg);

/// unit vector towards the sun in the world frame (x east, y north, z up) from apparent
/// elevation and azimuth (clockwise from north).
Eigen::Vector3d SunDirectionEnu(const SunPosition& p);

/// sky luminance multiplier for a geometric sun elevation (see the file header): 1 at and
/// above 0 deg, 8.5e-3 at -6 deg, 2e-5 at -12 deg, 2.5e-6 at and below -18 deg.
double TwilightSkyScale(double geometric_elevation_deg);

/// direct (beam) sunlight relative to the sun at the zenith, for an apparent elevation in
/// degrees: 0.7^(AM^0.678) / 0.7 with the relative air mass AM of Kasten and Young, "Revised
/// optical air mass tables and approximation formula", Applied Optics 28(22), 1989:
/// AM = 1 / (sin h + 0.50572 (h + 6.07995 deg)^-1.6364), and the clear-sky beam attenuation
/// of Meinel and Meinel, "Applied Solar Energy", 1976. 1 at the zenith, about 0.02 at the
/// horizon, 0 below it.
double DirectSunAttenuation(double elevation_deg);

}  // namespace penumbra
