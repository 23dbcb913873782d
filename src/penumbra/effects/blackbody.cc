#include "penumbra/effects/blackbody.h"

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

namespace penumbra {

namespace {

// piecewise Gaussian lobe of Wyman et al. 2013: width s1 below the mean, s2 above.
double Lobe(double x, double mu, double s1, double s2) {
  const double t = (x - mu) / (x < mu ? s1 : s2);
  return std::exp(-0.5 * t * t);
}

constexpr double kH = 6.62607015e-34;  // Planck constant, J s
constexpr double kC = 299792458.0;     // speed of light, m/s
constexpr double kK = 1.380649e-23;    // Boltzmann constant, J/K
constexpr double kLmPerW = 683.0;      // luminous efficacy at 555 nm (SI candela definition)

constexpr double kTableMinK = 300, kTableMaxK = 4000, kTableStepK = 10;
constexpr int kTableSize = static_cast<int>((kTableMaxK - kTableMinK) / kTableStepK) + 1;

struct Table {
  std::vector<Eigen::Vector3f> color;
  std::vector<double> log_luminance;
  Table() : color(kTableSize), log_luminance(kTableSize) {
    for (int i = 0; i < kTableSize; ++i) {
      const double T = kTableMinK + kTableStepK * i;
      color[i] = BlackbodyLinearSrgb(T).cast<float>();
      log_luminance[i] = std::log(std::max(BlackbodyLuminance(T), 1e-300));
    }
  }
};

const Table& GetTable() {
  static const Table kTable;
  return kTable;
}

}  // namespace

Eigen::Vector3d CieXyzBar(double l) {
  const double x = 1.056 * Lobe(l, 599.8, 37.9, 31.0) + 0.362 * Lobe(l, 442.0, 16.0, 26.7) -
                   0.065 * Lobe(l, 501.1, 20.4, 26.2);
  const double y = 0.821 * Lobe(l, 568.8, 46.9, 40.5) + 0.286 * Lobe(l, 530.9, 16.3, 31.1);
  const double z = 1.217 * Lobe(l, 437.0, 11.8, 36.0) + 0.681 * Lobe(l, 459.0, 26.0, 13.8);
  return {x, y, z};
}

double PlanckRadiance(double lambda_nm, double T_k) {
  const double l = lambda_nm * 1e-9;
  const double a = kH * kC / (l * kK * T_k);
  // W sr^-1 m^-3 -> per nm
  return 2.0 * kH * kC * kC / std::pow(l, 5) / std::expm1(a) * 1e-9;
}

Eigen::Vector3d BlackbodyXyz(double T_k) {
  // composite Simpson over [360, 830] nm with 1 nm steps (470 intervals, even)
  constexpr double kLo = 360, kHi = 830;
  constexpr int kN = 470;
  const double h = (kHi - kLo) / kN;
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (int i = 0; i <= kN; ++i) {
    const double l = kLo + h * i;
    const double wgt = (i == 0 || i == kN) ? 1.0 : (i % 2 ? 4.0 : 2.0);
    sum += wgt * PlanckRadiance(l, T_k) * CieXyzBar(l);
  }
  return sum * (h / 3.0);
}

Eigen::Vector3d XyzToLinearSrgb(const Eigen::Vector3d& xyz) {
  Eigen::Matrix3d m;
  m << 3.2406, -1.5372, -0.4986,  //
      -0.9689, 1.8758, 0.0415,    //
      0.0557, -0.2040, 1.0570;
  return m * xyz;
}

Eigen::Vector3d BlackbodyLinearSrgb(double T_k) {
  Eigen::Vector3d rgb = XyzToLinearSrgb(BlackbodyXyz(T_k)).cwiseMax(0.0);
  const double mx = rgb.maxCoeff();
  return mx > 0 ? Eigen::Vector3d(rgb / mx) : Eigen::Vector3d(0, 0, 0);
}

double BlackbodyLuminance(double T_k) { return kLmPerW * BlackbodyXyz(T_k).y(); }

double LinearSrgbLuminance(const Eigen::Vector3d& rgb) {
  return 0.2126 * rgb.x() + 0.7152 * rgb.y() + 0.0722 * rgb.z();
}

Eigen::Vector3f BlackbodyTable::Color(double T_k) {
  const Table& t = GetTable();
  const double x = std::clamp((T_k - kTableMinK) / kTableStepK, 0.0, kTableSize - 1.0);
  const int i = std::min(static_cast<int>(x), kTableSize - 2);
  const float f = static_cast<float>(x - i);
  return t.color[i] * (1 - f) + t.color[i + 1] * f;
}

double BlackbodyTable::Luminance(double T_k) {
  const Table& t = GetTable();
  const double x = std::clamp((T_k - kTableMinK) / kTableStepK, 0.0, kTableSize - 1.0);
  const int i = std::min(static_cast<int>(x), kTableSize - 2);
  const double f = x - i;
  return std::exp(t.log_luminance[i] * (1 - f) + t.log_luminance[i + 1] * f);
}

}  // namespace penumbra
