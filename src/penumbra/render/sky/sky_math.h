#pragma once
// daylight by the numbers: the sun's direct-normal illuminance and the clear sky's diffuse
// horizontal illuminance for a solar elevation and a turbidity. shared host/device formulas
// (core/host_device.h, /work/coord/shading_contract.md): scalar float, no Eigen, no exceptions.
//
// models (all photometric, lux):
//  - relative optical air mass m(h): Kasten and Young, "Revised optical air mass tables and
//    approximation formula", Applied Optics 28(22), 4735-4738, 1989:
//      m = 1 / (sin h + 0.50572 (h + 6.07995 deg)^-1.6364), h the elevation in degrees.
//  - luminous extinction of a clean, dry (Rayleigh) atmosphere: Navvab, Karayel, Ne'eman,
//    Selkowitz, "Analysis of atmospheric turbidity for daylight calculations", Energy and
//    Buildings 6, 293-303, 1984: a_v(m) = 1 / (9.9 + 0.043 m).
//  - direct-normal illuminance through a turbid atmosphere, the definition of the luminous
//    turbidity factor T_v (CIE S 017:2020, term 17-29-108): E_n = E_v0 exp(-a_v T_v m), with the
//    luminous solar constant E_v0 = 133.8 klx (Darula, Kittler, Gueymard, "Reference luminous
//    solar constant and solar luminance for illuminance calculations", Solar Energy 79(5),
//    559-565, 2005). Preetham, Shirley and Smits (SIGGRAPH 1999) define their turbidity T the
//    same way (optical thickness of haze and molecules over that of molecules alone), so the
//    sky model's T is used as T_v.
//  - diffuse horizontal illuminance of the clear sky: half of the light scattered out of the
//    beam reaches the ground (the Rayleigh term 0.5 (1 - T_R) of Bird and Hulstrom, "A
//    simplified clear sky model for direct and diffuse insolation on horizontal surfaces",
//    SERI/TR-642-761, 1981, applied to the whole luminous extinction):
//      D = 0.5 E_v0 sin h (1 - exp(-a_v T_v m)).
//    checked against the IES clear-sky model (IESNA Lighting Handbook, 9th ed., ch. 8:
//    E_dn = 127.5 klx exp(-0.21 m), E_kh = 0.8 + 15.5 sin^0.5 h klx) in tests/render/
//    sky_math_test.cc: within 15 % (sun) and 25 % (sky) at 20, 45 and 70 deg for T = 2.5.

#include <cmath>

#include "penumbra/core/host_device.h"

namespace penumbra {

/// luminous solar constant, lux (Darula, Kittler and Gueymard 2005).
inline constexpr float kLuminousSolarConstantLux = 133800.0f;

/// fraction of the light scattered out of the sun's beam that reaches the ground as sky light.
inline constexpr float kDiffuseDownwardFraction = 0.5f;

/// relative optical air mass at solar elevation `elevation_deg` (degrees, clamped to [0, 90]);
/// 1 at the zenith, about 38 at the horizon (Kasten and Young 1989).
PB_HOST_DEVICE inline float RelativeAirMass(float elevation_deg) {
  const float h = elevation_deg < 0.0f ? 0.0f : (elevation_deg > 90.0f ? 90.0f : elevation_deg);
  const float sin_h = sinf(h * 0.017453292519943295f);
  return 1.0f / (sin_h + 0.50572f * powf(h + 6.07995f, -1.6364f));
}

/// luminous extinction coefficient of a clean, dry atmosphere at air mass m (Navvab et al. 1984).
PB_HOST_DEVICE inline float RayleighLuminousExtinction(float air_mass) {
  return 1.0f / (9.9f + 0.043f * air_mass);
}

/// transmittance of the sun's beam (luminous, 0..1) at solar elevation `elevation_deg` through
/// an atmosphere of luminous turbidity `turbidity` (>= 1): exp(-a_v T m). 0 below the horizon.
PB_HOST_DEVICE inline float SunBeamTransmittance(float elevation_deg, float turbidity) {
  if (!(elevation_deg > 0.0f)) return 0.0f;
  const float m = RelativeAirMass(elevation_deg);
  return expf(-RayleighLuminousExtinction(m) * turbidity * m);
}

/// direct-normal illuminance of the sun (lux, on a surface facing the sun) at solar elevation
/// `elevation_deg` and turbidity `turbidity`; 0 below the horizon.
PB_HOST_DEVICE inline float SunDirectNormalIlluminance(float elevation_deg, float turbidity) {
  return kLuminousSolarConstantLux * SunBeamTransmittance(elevation_deg, turbidity);
}

/// diffuse horizontal illuminance of the clear sky (lux, on an unobstructed horizontal surface,
/// sun excluded) at solar elevation `elevation_deg` and turbidity `turbidity`; 0 below the horizon.
PB_HOST_DEVICE inline float SkyDiffuseHorizontalIlluminance(float elevation_deg, float turbidity) {
  if (!(elevation_deg > 0.0f)) return 0.0f;
  const float h = elevation_deg > 90.0f ? 90.0f : elevation_deg;
  const float sin_h = sinf(h * 0.017453292519943295f);
  return kDiffuseDownwardFraction * kLuminousSolarConstantLux * sin_h *
         (1.0f - SunBeamTransmittance(h, turbidity));
}

/// the cube-map lookup direction (qx, qy, qz) of a world direction (dx, dy, dz) for a MuJoCo
/// skybox: MuJoCo keeps cube faces in OpenGL's convention (+y up: its builtin gradient puts rgb1
/// on the +y face) and turns the skybox by 90 deg about x so that the cube's +y is the world's
/// +z: q = (dx, dz, -dy).
PB_HOST_DEVICE inline void SkyboxLookupDirection(float dx, float dy, float dz, float* qx, float* qy,
                                                 float* qz) {
  *qx = dx;
  *qy = dz;
  *qz = -dy;
}

/// face (0..5: +x, -x, +y, -y, +z, -z) and face coordinates (s, t) in [0, 1] of cube-map
/// direction q, per the OpenGL 4.6 core specification, table 8.19 (t = 0 is the face's first
/// row). returns false for a zero direction.
PB_HOST_DEVICE inline bool CubeFaceCoords(float qx, float qy, float qz, int* face, float* s,
                                          float* t) {
  const float ax = fabsf(qx), ay = fabsf(qy), az = fabsf(qz);
  float sc, tc, ma;
  if (ax >= ay && ax >= az) {
    ma = ax;
    *face = qx >= 0.0f ? 0 : 1;
    sc = qx >= 0.0f ? -qz : qz;
    tc = -qy;
  } else if (ay >= az) {
    ma = ay;
    *face = qy >= 0.0f ? 2 : 3;
    sc = qx;
    tc = qy >= 0.0f ? qz : -qz;
  } else {
    ma = az;
    *face = qz >= 0.0f ? 4 : 5;
    sc = qz >= 0.0f ? qx : -qx;
    tc = -qy;
  }
  if (!(ma > 0.0f)) return false;
  *s = 0.5f * (sc / ma + 1.0f);
  *t = 0.5f * (tc / ma + 1.0f);
  return true;
}

}  // namespace penumbra
