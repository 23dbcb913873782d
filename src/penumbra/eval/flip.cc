#include "penumbra/eval/flip.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include "penumbra/core/error.h"
#include "penumbra/core/srgb.h"

namespace penumbra {
namespace {

// the model's constants (the paper's sections 3 and 4 and its table of CSF parameters)
constexpr double kFlipQc = 0.7;              // exponent of the HyAB colour distance
constexpr double kFlipPc = 0.4;              // colour remap knee, as a fraction of cmax
constexpr double kFlipPt = 0.95;             // the remapped value at the knee
constexpr double kFlipEdgeWidthDeg = 0.082;  // peak-to-trough width of the edge detector, deg
constexpr double kFlipQf = 0.5;              // exponent of the feature difference
// contrast sensitivity functions as sums of Gaussians a sqrt(pi / b) exp(-pi^2 x^2 / b), x in
// degrees: achromatic (one Gaussian), red-green (one), blue-yellow (two)
constexpr double kFlipBAchromatic = 0.0047;
constexpr double kFlipBRedGreen = 0.0053;
constexpr double kFlipA1BlueYellow = 34.1, kFlipB1BlueYellow = 0.04;
constexpr double kFlipA2BlueYellow = 13.5, kFlipB2BlueYellow = 0.025;
constexpr double kFlipBMax = kFlipB1BlueYellow;  // the widest of the b's sets the radius

// matplotlib's magma colour map (CC0; S. van der Walt and N. Smith), the 256 entries FLIP uses,
// RGB in [0, 1]
constexpr float kFlipMagma[256][3] = {
    {0.001462f, 0.000466f, 0.013866f}, {0.002258f, 0.001295f, 0.018331f},
    {0.003279f, 0.002305f, 0.023708f}, {0.004512f, 0.003490f, 0.029965f},
    {0.005950f, 0.004843f, 0.037130f}, {0.007588f, 0.006356f, 0.044973f},
    {0.009426f, 0.008022f, 0.052844f}, {0.011465f, 0.009828f, 0.060750f},
    {0.013708f, 0.011771f, 0.068667f}, {0.016156f, 0.013840f, 0.076603f},
    {0.018815f, 0.016026f, 0.084584f}, {0.021692f, 0.018320f, 0.092610f},
    {0.024792f, 0.020715f, 0.100676f}, {0.028123f, 0.023201f, 0.108787f},
    {0.031696f, 0.025765f, 0.116965f}, {0.035520f, 0.028397f, 0.125209f},
    {0.039608f, 0.031090f, 0.133515f}, {0.043830f, 0.033830f, 0.141886f},
    {0.048062f, 0.036607f, 0.150327f}, {0.052320f, 0.039407f, 0.158841f},
    {0.056615f, 0.042160f, 0.167446f}, {0.060949f, 0.044794f, 0.176129f},
    {0.065330f, 0.047318f, 0.184892f}, {0.069764f, 0.049726f, 0.193735f},
    {0.074257f, 0.052017f, 0.202660f}, {0.078815f, 0.054184f, 0.211667f},
    {0.083446f, 0.056225f, 0.220755f}, {0.088155f, 0.058133f, 0.229922f},
    {0.092949f, 0.059904f, 0.239164f}, {0.097833f, 0.061531f, 0.248477f},
    {0.102815f, 0.063010f, 0.257854f}, {0.107899f, 0.064335f, 0.267289f},
    {0.113094f, 0.065492f, 0.276784f}, {0.118405f, 0.066479f, 0.286321f},
    {0.123833f, 0.067295f, 0.295879f}, {0.129380f, 0.067935f, 0.305443f},
    {0.135053f, 0.068391f, 0.315000f}, {0.140858f, 0.068654f, 0.324538f},
    {0.146785f, 0.068738f, 0.334011f}, {0.152839f, 0.068637f, 0.343404f},
    {0.159018f, 0.068354f, 0.352688f}, {0.165308f, 0.067911f, 0.361816f},
    {0.171713f, 0.067305f, 0.370771f}, {0.178212f, 0.066576f, 0.379497f},
    {0.184801f, 0.065732f, 0.387973f}, {0.191460f, 0.064818f, 0.396152f},
    {0.198177f, 0.063862f, 0.404009f}, {0.204935f, 0.062907f, 0.411514f},
    {0.211718f, 0.061992f, 0.418647f}, {0.218512f, 0.061158f, 0.425392f},
    {0.225302f, 0.060445f, 0.431742f}, {0.232077f, 0.059889f, 0.437695f},
    {0.238826f, 0.059517f, 0.443256f}, {0.245543f, 0.059352f, 0.448436f},
    {0.252220f, 0.059415f, 0.453248f}, {0.258857f, 0.059706f, 0.457710f},
    {0.265447f, 0.060237f, 0.461840f}, {0.271994f, 0.060994f, 0.465660f},
    {0.278493f, 0.061978f, 0.469190f}, {0.284951f, 0.063168f, 0.472451f},
    {0.291366f, 0.064553f, 0.475462f}, {0.297740f, 0.066117f, 0.478243f},
    {0.304081f, 0.067835f, 0.480812f}, {0.310382f, 0.069702f, 0.483186f},
    {0.316654f, 0.071690f, 0.485380f}, {0.322899f, 0.073782f, 0.487408f},
    {0.329114f, 0.075972f, 0.489287f}, {0.335308f, 0.078236f, 0.491024f},
    {0.341482f, 0.080564f, 0.492631f}, {0.347636f, 0.082946f, 0.494121f},
    {0.353773f, 0.085373f, 0.495501f}, {0.359898f, 0.087831f, 0.496778f},
    {0.366012f, 0.090314f, 0.497960f}, {0.372116f, 0.092816f, 0.499053f},
    {0.378211f, 0.095332f, 0.500067f}, {0.384299f, 0.097855f, 0.501002f},
    {0.390384f, 0.100379f, 0.501864f}, {0.396467f, 0.102902f, 0.502658f},
    {0.402548f, 0.105420f, 0.503386f}, {0.408629f, 0.107930f, 0.504052f},
    {0.414709f, 0.110431f, 0.504662f}, {0.420791f, 0.112920f, 0.505215f},
    {0.426877f, 0.115395f, 0.505714f}, {0.432967f, 0.117855f, 0.506160f},
    {0.439062f, 0.120298f, 0.506555f}, {0.445163f, 0.122724f, 0.506901f},
    {0.451271f, 0.125132f, 0.507198f}, {0.457386f, 0.127522f, 0.507448f},
    {0.463508f, 0.129893f, 0.507652f}, {0.469640f, 0.132245f, 0.507809f},
    {0.475780f, 0.134577f, 0.507921f}, {0.481929f, 0.136891f, 0.507989f},
    {0.488088f, 0.139186f, 0.508011f}, {0.494258f, 0.141462f, 0.507988f},
    {0.500438f, 0.143719f, 0.507920f}, {0.506629f, 0.145958f, 0.507806f},
    {0.512831f, 0.148179f, 0.507648f}, {0.519045f, 0.150383f, 0.507443f},
    {0.525270f, 0.152569f, 0.507192f}, {0.531507f, 0.154739f, 0.506895f},
    {0.537755f, 0.156894f, 0.506551f}, {0.544015f, 0.159033f, 0.506159f},
    {0.550287f, 0.161158f, 0.505719f}, {0.556571f, 0.163269f, 0.505230f},
    {0.562866f, 0.165368f, 0.504692f}, {0.569172f, 0.167454f, 0.504105f},
    {0.575490f, 0.169530f, 0.503466f}, {0.581819f, 0.171596f, 0.502777f},
    {0.588158f, 0.173652f, 0.502035f}, {0.594508f, 0.175701f, 0.501241f},
    {0.600868f, 0.177743f, 0.500394f}, {0.607238f, 0.179779f, 0.499492f},
    {0.613617f, 0.181811f, 0.498536f}, {0.620005f, 0.183840f, 0.497524f},
    {0.626401f, 0.185867f, 0.496456f}, {0.632805f, 0.187893f, 0.495332f},
    {0.639216f, 0.189921f, 0.494150f}, {0.645633f, 0.191952f, 0.492910f},
    {0.652056f, 0.193986f, 0.491611f}, {0.658483f, 0.196027f, 0.490253f},
    {0.664915f, 0.198075f, 0.488836f}, {0.671349f, 0.200133f, 0.487358f},
    {0.677786f, 0.202203f, 0.485819f}, {0.684224f, 0.204286f, 0.484219f},
    {0.690661f, 0.206384f, 0.482558f}, {0.697098f, 0.208501f, 0.480835f},
    {0.703532f, 0.210638f, 0.479049f}, {0.709962f, 0.212797f, 0.477201f},
    {0.716387f, 0.214982f, 0.475290f}, {0.722805f, 0.217194f, 0.473316f},
    {0.729216f, 0.219437f, 0.471279f}, {0.735616f, 0.221713f, 0.469180f},
    {0.742004f, 0.224025f, 0.467018f}, {0.748378f, 0.226377f, 0.464794f},
    {0.754737f, 0.228772f, 0.462509f}, {0.761077f, 0.231214f, 0.460162f},
    {0.767398f, 0.233705f, 0.457755f}, {0.773695f, 0.236249f, 0.455289f},
    {0.779968f, 0.238851f, 0.452765f}, {0.786212f, 0.241514f, 0.450184f},
    {0.792427f, 0.244242f, 0.447543f}, {0.798608f, 0.247040f, 0.444848f},
    {0.804752f, 0.249911f, 0.442102f}, {0.810855f, 0.252861f, 0.439305f},
    {0.816914f, 0.255895f, 0.436461f}, {0.822926f, 0.259016f, 0.433573f},
    {0.828886f, 0.262229f, 0.430644f}, {0.834791f, 0.265540f, 0.427671f},
    {0.840636f, 0.268953f, 0.424666f}, {0.846416f, 0.272473f, 0.421631f},
    {0.852126f, 0.276106f, 0.418573f}, {0.857763f, 0.279857f, 0.415496f},
    {0.863320f, 0.283729f, 0.412403f}, {0.868793f, 0.287728f, 0.409303f},
    {0.874176f, 0.291859f, 0.406205f}, {0.879464f, 0.296125f, 0.403118f},
    {0.884651f, 0.300530f, 0.400047f}, {0.889731f, 0.305079f, 0.397002f},
    {0.894700f, 0.309773f, 0.393995f}, {0.899552f, 0.314616f, 0.391037f},
    {0.904281f, 0.319610f, 0.388137f}, {0.908884f, 0.324755f, 0.385308f},
    {0.913354f, 0.330052f, 0.382563f}, {0.917689f, 0.335500f, 0.379915f},
    {0.921884f, 0.341098f, 0.377376f}, {0.925937f, 0.346844f, 0.374959f},
    {0.929845f, 0.352734f, 0.372677f}, {0.933606f, 0.358764f, 0.370541f},
    {0.937221f, 0.364929f, 0.368567f}, {0.940687f, 0.371224f, 0.366762f},
    {0.944006f, 0.377643f, 0.365136f}, {0.947180f, 0.384178f, 0.363701f},
    {0.950210f, 0.390820f, 0.362468f}, {0.953099f, 0.397563f, 0.361438f},
    {0.955849f, 0.404400f, 0.360619f}, {0.958464f, 0.411324f, 0.360014f},
    {0.960949f, 0.418323f, 0.359630f}, {0.963310f, 0.425390f, 0.359469f},
    {0.965549f, 0.432519f, 0.359529f}, {0.967671f, 0.439703f, 0.359810f},
    {0.969680f, 0.446936f, 0.360311f}, {0.971582f, 0.454210f, 0.361030f},
    {0.973381f, 0.461520f, 0.361965f}, {0.975082f, 0.468861f, 0.363111f},
    {0.976690f, 0.476226f, 0.364466f}, {0.978210f, 0.483612f, 0.366025f},
    {0.979645f, 0.491014f, 0.367783f}, {0.981000f, 0.498428f, 0.369734f},
    {0.982279f, 0.505851f, 0.371874f}, {0.983485f, 0.513280f, 0.374198f},
    {0.984622f, 0.520713f, 0.376698f}, {0.985693f, 0.528148f, 0.379371f},
    {0.986700f, 0.535582f, 0.382210f}, {0.987646f, 0.543015f, 0.385210f},
    {0.988533f, 0.550446f, 0.388365f}, {0.989363f, 0.557873f, 0.391671f},
    {0.990138f, 0.565296f, 0.395122f}, {0.990871f, 0.572706f, 0.398714f},
    {0.991558f, 0.580107f, 0.402441f}, {0.992196f, 0.587502f, 0.406299f},
    {0.992785f, 0.594891f, 0.410283f}, {0.993326f, 0.602275f, 0.414390f},
    {0.993834f, 0.609644f, 0.418613f}, {0.994309f, 0.616999f, 0.422950f},
    {0.994738f, 0.624350f, 0.427397f}, {0.995122f, 0.631696f, 0.431951f},
    {0.995480f, 0.639027f, 0.436607f}, {0.995810f, 0.646344f, 0.441361f},
    {0.996096f, 0.653659f, 0.446213f}, {0.996341f, 0.660969f, 0.451160f},
    {0.996580f, 0.668256f, 0.456192f}, {0.996775f, 0.675541f, 0.461314f},
    {0.996925f, 0.682828f, 0.466526f}, {0.997077f, 0.690088f, 0.471811f},
    {0.997186f, 0.697349f, 0.477182f}, {0.997254f, 0.704611f, 0.482635f},
    {0.997325f, 0.711848f, 0.488154f}, {0.997351f, 0.719089f, 0.493755f},
    {0.997351f, 0.726324f, 0.499428f}, {0.997341f, 0.733545f, 0.505167f},
    {0.997285f, 0.740772f, 0.510983f}, {0.997228f, 0.747981f, 0.516859f},
    {0.997138f, 0.755190f, 0.522806f}, {0.997019f, 0.762398f, 0.528821f},
    {0.996898f, 0.769591f, 0.534892f}, {0.996727f, 0.776795f, 0.541039f},
    {0.996571f, 0.783977f, 0.547233f}, {0.996369f, 0.791167f, 0.553499f},
    {0.996162f, 0.798348f, 0.559820f}, {0.995932f, 0.805527f, 0.566202f},
    {0.995680f, 0.812706f, 0.572645f}, {0.995424f, 0.819875f, 0.579140f},
    {0.995131f, 0.827052f, 0.585701f}, {0.994851f, 0.834213f, 0.592307f},
    {0.994524f, 0.841387f, 0.598983f}, {0.994222f, 0.848540f, 0.605696f},
    {0.993866f, 0.855711f, 0.612482f}, {0.993545f, 0.862859f, 0.619299f},
    {0.993170f, 0.870024f, 0.626189f}, {0.992831f, 0.877168f, 0.633109f},
    {0.992440f, 0.884330f, 0.640099f}, {0.992089f, 0.891470f, 0.647116f},
    {0.991688f, 0.898627f, 0.654202f}, {0.991332f, 0.905763f, 0.661309f},
    {0.990930f, 0.912915f, 0.668481f}, {0.990570f, 0.920049f, 0.675675f},
    {0.990175f, 0.927196f, 0.682926f}, {0.989815f, 0.934329f, 0.690198f},
    {0.989434f, 0.941470f, 0.697519f}, {0.989077f, 0.948604f, 0.704863f},
    {0.988717f, 0.955742f, 0.712242f}, {0.988367f, 0.962878f, 0.719649f},
    {0.988033f, 0.970012f, 0.727077f}, {0.987691f, 0.977154f, 0.734536f},
    {0.987387f, 0.984288f, 0.742002f}, {0.987053f, 0.991438f, 0.749504f},
};

// one channel of an image, row-major
struct FlipPlane {
  int w = 0, h = 0;
  std::vector<float> v;
  FlipPlane() = default;
  FlipPlane(int width, int height) : w(width), h(height), v(static_cast<size_t>(width) * height) {}
};

// linear sRGB <-> CIE XYZ from the sRGB primaries and D65 white (IEC 61966-2-1 chromaticities),
// and the sRGB decoding of each 8-bit value
struct FlipColourSpace {
  float rgb_to_xyz[3][3];
  float xyz_to_rgb[3][3];
  float white[3];      // XYZ of linear RGB (1, 1, 1): D65 with Y = 1
  float inv_white[3];  // 1 / white
  float decode[256];   // sRGB 8-bit value -> linear [0, 1]
};

FlipColourSpace MakeFlipColourSpace() {
  const double xy[4][2] = {{0.64, 0.33}, {0.30, 0.60}, {0.15, 0.06}, {0.3127, 0.3290}};
  Eigen::Matrix3d P;  // columns: XYZ of each primary at Y = 1
  for (int c = 0; c < 3; ++c)
    P.col(c) << xy[c][0] / xy[c][1], 1.0, (1.0 - xy[c][0] - xy[c][1]) / xy[c][1];
  const Eigen::Vector3d W(xy[3][0] / xy[3][1], 1.0, (1.0 - xy[3][0] - xy[3][1]) / xy[3][1]);
  const Eigen::Vector3d S = P.colPivHouseholderQr().solve(W);
  const Eigen::Matrix3d M = P * S.asDiagonal();
  const Eigen::Matrix3d Minv = M.inverse();
  FlipColourSpace cs{};
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) {
      cs.rgb_to_xyz[r][c] = static_cast<float>(M(r, c));
      cs.xyz_to_rgb[r][c] = static_cast<float>(Minv(r, c));
    }
    cs.white[r] = static_cast<float>(W(r));
    cs.inv_white[r] = static_cast<float>(1.0 / W(r));
  }
  for (int i = 0; i < 256; ++i) cs.decode[i] = static_cast<float>(SrgbToLinear(i / 255.0));
  return cs;
}

const FlipColourSpace& FlipColours() {
  static const FlipColourSpace cs = MakeFlipColourSpace();
  return cs;
}

// linear RGB -> CIELAB (D65) with FLIP's Hunt adjustment (a and b scaled by 0.01 L)
void FlipLabHunt(const FlipColourSpace& cs, const float rgb[3], float lab[3]) {
  constexpr float kDelta = 6.0f / 29.0f;
  constexpr float kDeltaCube = kDelta * kDelta * kDelta;
  constexpr float kSlope = 1.0f / (3.0f * kDelta * kDelta);
  constexpr float kOffset = 4.0f / 29.0f;
  float f[3];
  for (int r = 0; r < 3; ++r) {
    const float t = (cs.rgb_to_xyz[r][0] * rgb[0] + cs.rgb_to_xyz[r][1] * rgb[1] +
                     cs.rgb_to_xyz[r][2] * rgb[2]) *
                    cs.inv_white[r];
    f[r] = t > kDeltaCube ? std::cbrt(t) : kSlope * t + kOffset;
  }
  const float L = 116.0f * f[1] - 16.0f;
  lab[0] = L;
  lab[1] = 0.01f * L * 500.0f * (f[0] - f[1]);
  lab[2] = 0.01f * L * 200.0f * (f[1] - f[2]);
}

float FlipHyab(const float p[3], const float q[3]) {
  return std::fabs(p[0] - q[0]) + std::hypot(p[1] - q[1], p[2] - q[2]);
}

// a 1D kernel of 2 r + 1 taps, tap i at offset i - r
using FlipKernel = std::vector<float>;

struct FlipKernels {
  FlipKernel achromatic, red_green, blue_yellow_1, blue_yellow_2;  // colour (CSF) filters
  FlipKernel gauss, edge, point;  // feature detection: Gaussian, 1st and 2nd derivative
};

// positive taps scaled to sum to 1 and negative ones to -1 (a sum of 0 leaves its taps 0)
FlipKernel FlipSignNormalized(const std::vector<double>& k) {
  double pos = 0, neg = 0;
  for (double v : k) (v > 0 ? pos : neg) += std::fabs(v);
  FlipKernel out(k.size(), 0.0f);
  for (size_t i = 0; i < k.size(); ++i) {
    if (k[i] > 0 && pos > 0) out[i] = static_cast<float>(k[i] / pos);
    if (k[i] < 0 && neg > 0) out[i] = static_cast<float>(k[i] / neg);
  }
  return out;
}

FlipKernels MakeFlipKernels(double ppd) {
  constexpr double kPi = std::numbers::pi;
  FlipKernels k;
  // colour: the 2D kernel is g(x) g(y) for one Gaussian, so each 1D pass is the Gaussian
  // normalized to sum 1; blue-yellow's sum of two is c1(x) c1(y) + c2(x) c2(y) with
  // c_k = sqrt(a_k sqrt(pi / b_k)) exp(-pi^2 x^2 / b_k), both scaled by 1 / sqrt(S1^2 + S2^2)
  // (S_k = sum of c_k) so the 2D kernel sums to 1
  const int r = static_cast<int>(std::ceil(3.0 * std::sqrt(kFlipBMax / (2.0 * kPi * kPi)) * ppd));
  std::vector<double> ga, grg, c1, c2;
  double sa = 0, srg = 0, s1 = 0, s2 = 0;
  for (int i = -r; i <= r; ++i) {
    const double x2 = (i / ppd) * (i / ppd);
    ga.push_back(std::exp(-kPi * kPi * x2 / kFlipBAchromatic));
    grg.push_back(std::exp(-kPi * kPi * x2 / kFlipBRedGreen));
    c1.push_back(std::sqrt(kFlipA1BlueYellow * std::sqrt(kPi / kFlipB1BlueYellow)) *
                 std::exp(-kPi * kPi * x2 / kFlipB1BlueYellow));
    c2.push_back(std::sqrt(kFlipA2BlueYellow * std::sqrt(kPi / kFlipB2BlueYellow)) *
                 std::exp(-kPi * kPi * x2 / kFlipB2BlueYellow));
    sa += ga.back();
    srg += grg.back();
    s1 += c1.back();
    s2 += c2.back();
  }
  const double s12 = std::sqrt(s1 * s1 + s2 * s2);
  for (size_t i = 0; i < ga.size(); ++i) {
    k.achromatic.push_back(static_cast<float>(ga[i] / sa));
    k.red_green.push_back(static_cast<float>(grg[i] / srg));
    k.blue_yellow_1.push_back(static_cast<float>(c1[i] / s12));
    k.blue_yellow_2.push_back(static_cast<float>(c2[i] / s12));
  }
  // features: a Gaussian of sd = half the edge detector's peak-to-trough width, and its first
  // and second derivatives along one axis
  const double sd = 0.5 * kFlipEdgeWidthDeg * ppd;
  const int rf = static_cast<int>(std::ceil(3.0 * sd));
  std::vector<double> g, dg, ddg;
  double sg = 0;
  for (int i = -rf; i <= rf; ++i) {
    const double e = std::exp(-(double(i) * i) / (2.0 * sd * sd));
    g.push_back(e);
    dg.push_back(-i * e);
    ddg.push_back((double(i) * i / (sd * sd) - 1.0) * e);
    sg += e;
  }
  for (double v : g) k.gauss.push_back(static_cast<float>(v / sg));
  k.edge = FlipSignNormalized(dg);
  k.point = FlipSignNormalized(ddg);
  return k;
}

// out(x, y) = sum_i k[i] in(x + i - r, y), x + i - r clamped to the image (edge repeated)
void FlipFilterRows(const FlipPlane& in, const FlipKernel& k, FlipPlane* out) {
  const int r = static_cast<int>(k.size() / 2);
  const int w = in.w;
  *out = FlipPlane(in.w, in.h);
  std::vector<float> padded(static_cast<size_t>(w) + 2 * r);
  for (int y = 0; y < in.h; ++y) {
    const float* row = in.v.data() + static_cast<size_t>(y) * w;
    for (int x = -r; x < w + r; ++x) padded[x + r] = row[std::clamp(x, 0, w - 1)];
    float* dst = out->v.data() + static_cast<size_t>(y) * w;
    for (int x = 0; x < w; ++x) {
      float s = 0;
      for (size_t i = 0; i < k.size(); ++i) s += k[i] * padded[x + i];
      dst[x] = s;
    }
  }
}

// out(x, y) = sum_i k[i] in(x, y + i - r), y + i - r clamped; added to `out` when accumulate
void FlipFilterColumns(const FlipPlane& in, const FlipKernel& k, FlipPlane* out,
                       bool accumulate = false) {
  const int r = static_cast<int>(k.size() / 2);
  const int w = in.w;
  if (!accumulate) *out = FlipPlane(in.w, in.h);
  std::vector<float> acc(w);
  for (int y = 0; y < in.h; ++y) {
    std::fill(acc.begin(), acc.end(), 0.0f);
    for (size_t i = 0; i < k.size(); ++i) {
      const int yy = std::clamp(y + static_cast<int>(i) - r, 0, in.h - 1);
      const float* src = in.v.data() + static_cast<size_t>(yy) * w;
      const float ki = k[i];
      for (int x = 0; x < w; ++x) acc[x] += ki * src[x];
    }
    float* dst = out->v.data() + static_cast<size_t>(y) * w;
    for (int x = 0; x < w; ++x) dst[x] = accumulate ? dst[x] + acc[x] : acc[x];
  }
}

// what FLIP compares of one image: per pixel the filtered colour in Hunt-adjusted CIELAB, and
// the edge and point magnitudes of its luminance
struct FlipAnalysis {
  FlipPlane L, a, b, edge, point;
};

FlipAnalysis AnalyseForFlip(const ImageU8& image, const FlipKernels& k) {
  const FlipColourSpace& cs = FlipColours();
  const int w = image.width, h = image.height;
  // YCxCz: Y = 116 y - 16, Cx = 500 (x - y), Cz = 200 (y - z) of XYZ over the white's
  FlipPlane Y(w, h), Cx(w, h), Cz(w, h), lum(w, h);
  for (size_t p = 0; p < Y.v.size(); ++p) {
    const uint8_t* s = image.data.data() + 3 * p;
    const float rgb[3] = {cs.decode[s[0]], cs.decode[s[1]], cs.decode[s[2]]};
    float n[3];
    for (int r = 0; r < 3; ++r)
      n[r] = (cs.rgb_to_xyz[r][0] * rgb[0] + cs.rgb_to_xyz[r][1] * rgb[1] +
              cs.rgb_to_xyz[r][2] * rgb[2]) *
             cs.inv_white[r];
    Y.v[p] = 116.0f * n[1] - 16.0f;
    Cx.v[p] = 500.0f * (n[0] - n[1]);
    Cz.v[p] = 200.0f * (n[1] - n[2]);
    lum.v[p] = (Y.v[p] + 16.0f) / 116.0f;
  }
  FlipAnalysis out;
  FlipPlane tmp, fY, fCx, fCz;
  FlipFilterRows(Y, k.achromatic, &tmp);
  FlipFilterColumns(tmp, k.achromatic, &fY);
  FlipFilterRows(Cx, k.red_green, &tmp);
  FlipFilterColumns(tmp, k.red_green, &fCx);
  FlipFilterRows(Cz, k.blue_yellow_1, &tmp);
  FlipFilterColumns(tmp, k.blue_yellow_1, &fCz);
  FlipFilterRows(Cz, k.blue_yellow_2, &tmp);
  FlipFilterColumns(tmp, k.blue_yellow_2, &fCz, /*accumulate=*/true);
  Y = Cx = Cz = FlipPlane();
  // filtered YCxCz -> XYZ -> linear RGB clamped to [0, 1] -> Hunt-adjusted CIELAB
  out.L = FlipPlane(w, h);
  out.a = FlipPlane(w, h);
  out.b = FlipPlane(w, h);
  for (size_t p = 0; p < fY.v.size(); ++p) {
    const float yn = (fY.v[p] + 16.0f) / 116.0f;
    const float xyz[3] = {(yn + fCx.v[p] / 500.0f) * cs.white[0], yn * cs.white[1],
                          (yn - fCz.v[p] / 200.0f) * cs.white[2]};
    float rgb[3];
    for (int r = 0; r < 3; ++r)
      rgb[r] = std::clamp(cs.xyz_to_rgb[r][0] * xyz[0] + cs.xyz_to_rgb[r][1] * xyz[1] +
                              cs.xyz_to_rgb[r][2] * xyz[2],
                          0.0f, 1.0f);
    float lab[3];
    FlipLabHunt(cs, rgb, lab);
    out.L.v[p] = lab[0];
    out.a.v[p] = lab[1];
    out.b.v[p] = lab[2];
  }
  fY = fCx = fCz = FlipPlane();
  // features of the luminance in [0, 1]: x passes with the Gaussian and its derivatives, then
  // y passes: d/dx = (edge x, gauss y), d/dy = (gauss x, edge y), the same for points
  FlipPlane rg, rd, rdd, gx, gy;
  FlipFilterRows(lum, k.gauss, &rg);
  FlipFilterRows(lum, k.edge, &rd);
  FlipFilterRows(lum, k.point, &rdd);
  lum = FlipPlane();
  FlipFilterColumns(rd, k.gauss, &gx);
  FlipFilterColumns(rg, k.edge, &gy);
  out.edge = FlipPlane(w, h);
  for (size_t p = 0; p < gx.v.size(); ++p) out.edge.v[p] = std::hypot(gx.v[p], gy.v[p]);
  FlipFilterColumns(rdd, k.gauss, &gx);
  FlipFilterColumns(rg, k.point, &gy);
  out.point = FlipPlane(w, h);
  for (size_t p = 0; p < gx.v.size(); ++p) out.point.v[p] = std::hypot(gx.v[p], gy.v[p]);
  return out;
}

void CheckFlipInput(const ImageU8& image, const char* what) {
  if (image.width <= 0 || image.height <= 0 || image.channels != 3 ||
      image.data.size() != static_cast<size_t>(image.width) * image.height * 3)
    throw Error(std::string("FLIP: the ") + what + " image is " + std::to_string(image.width) +
                " x " + std::to_string(image.height) + " x " + std::to_string(image.channels) +
                " with " + std::to_string(image.data.size()) +
                " bytes; expected a non-empty (H x W x 3) uint8 image");
}

void CheckFlipMap(const ImageF& map) {
  if (map.width <= 0 || map.height <= 0 || map.channels != 1 ||
      map.data.size() != static_cast<size_t>(map.width) * map.height)
    throw Error("FLIP: the error map is " + std::to_string(map.width) + " x " +
                std::to_string(map.height) + " x " + std::to_string(map.channels) +
                "; expected a non-empty (H x W x 1) float image");
}

}  // namespace

double FlipPixelsPerDegree(double distance_m, double width_px, double width_m) {
  return distance_m * (width_px / width_m) * std::numbers::pi / 180.0;
}

ImageF FlipErrorMap(const ImageU8& reference, const ImageU8& test, double pixels_per_degree) {
  CheckFlipInput(reference, "reference");
  CheckFlipInput(test, "test");
  if (reference.width != test.width || reference.height != test.height)
    throw Error("FLIP: the reference is " + std::to_string(reference.width) + " x " +
                std::to_string(reference.height) + " pixels and the test " +
                std::to_string(test.width) + " x " + std::to_string(test.height) +
                "; expected the same size");
  if (!(pixels_per_degree > 0 && pixels_per_degree <= kFlipMaxPixelsPerDegree))
    throw Error("FLIP: pixels per degree " + std::to_string(pixels_per_degree) +
                "; expected a number in (0, " + std::to_string(kFlipMaxPixelsPerDegree) + "]");
  const FlipKernels k = MakeFlipKernels(pixels_per_degree);
  const FlipAnalysis ref = AnalyseForFlip(reference, k);
  const FlipAnalysis tst = AnalyseForFlip(test, k);

  // cmax: the remapped distance of pure green from pure blue
  const FlipColourSpace& cs = FlipColours();
  const float green[3] = {0, 1, 0}, blue[3] = {0, 0, 1};
  float green_lab[3], blue_lab[3];
  FlipLabHunt(cs, green, green_lab);
  FlipLabHunt(cs, blue, blue_lab);
  const float cmax = std::pow(FlipHyab(green_lab, blue_lab), static_cast<float>(kFlipQc));
  const float knee = static_cast<float>(kFlipPc) * cmax;
  const float pt = static_cast<float>(kFlipPt);

  ImageF map(reference.width, reference.height, 1);
  for (size_t p = 0; p < map.data.size(); ++p) {
    const float rp[3] = {ref.L.v[p], ref.a.v[p], ref.b.v[p]};
    const float tp[3] = {tst.L.v[p], tst.a.v[p], tst.b.v[p]};
    float colour = std::pow(FlipHyab(rp, tp), static_cast<float>(kFlipQc));
    colour =
        colour < knee ? colour * (pt / knee) : pt + (colour - knee) / (cmax - knee) * (1.0f - pt);
    const float edge = std::fabs(ref.edge.v[p] - tst.edge.v[p]);
    const float point = std::fabs(ref.point.v[p] - tst.point.v[p]);
    const float feature =
        std::pow(std::max(edge, point) / std::numbers::sqrt2_v<float>, static_cast<float>(kFlipQf));
    map.data[p] = std::pow(colour, 1.0f - feature);
  }
  return map;
}

FlipStats PoolFlipErrors(const ImageF& error_map) {
  CheckFlipMap(error_map);
  std::vector<float> sorted = error_map.data;
  std::sort(sorted.begin(), sorted.end());
  double sum = 0;
  for (float v : sorted) sum += v;
  FlipStats s;
  s.mean = sum / static_cast<double>(sorted.size());
  s.min = sorted.front();
  s.max = sorted.back();
  // weighted percentile: the first sorted value whose running sum exceeds p times the sum
  auto weighted = [&](double p) {
    double running = 0;
    for (float v : sorted) {
      running += v;
      if (running > p * sum) return static_cast<double>(v);
    }
    return 0.0;
  };
  s.weighted_median = weighted(0.5);
  s.weighted_q1 = weighted(0.25);
  s.weighted_q3 = weighted(0.75);
  return s;
}

std::array<float, 3> FlipMagmaColour(int i) {
  if (i < 0 || i > 255) throw Error("FLIP: magma entry " + std::to_string(i) + "; expected 0..255");
  return {kFlipMagma[i][0], kFlipMagma[i][1], kFlipMagma[i][2]};
}

ImageU8 FlipMagmaHeatmap(const ImageF& error_map) {
  CheckFlipMap(error_map);
  uint8_t lut[256][3];
  for (int i = 0; i < 256; ++i)
    for (int c = 0; c < 3; ++c)
      lut[i][c] = static_cast<uint8_t>(std::lround(255.0f * kFlipMagma[i][c]));
  ImageU8 out(error_map.width, error_map.height, 3);
  for (size_t p = 0; p < error_map.data.size(); ++p) {
    const float v = error_map.data[p];
    const float clamped = v > 0 ? std::min(v, 1.0f) : 0.0f;  // NaN -> 0
    const int i = static_cast<int>(clamped * 255.0f + 0.5f);
    std::copy(lut[i], lut[i] + 3, out.data.data() + 3 * p);
  }
  return out;
}

}  // namespace penumbra
