// the metallic-roughness BRDF: Lambertian limit, reciprocity, energy, and consistency of
// Sample / Eval / Pdf (what MIS relies on).

#include "penumbra/render/light/bsdf.h"

#include <gtest/gtest.h>

#include <cmath>

#include "penumbra/core/rng.h"

namespace penumbra {
namespace {

constexpr double kPi = M_PI;

Eigen::Vector3f Dir(double theta, double phi) {
  return Eigen::Vector3d(std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi),
                         std::cos(theta))
      .cast<float>();
}

PbrParams Params(float rough, float metal, Eigen::Vector3f base = {0.7f, 0.5f, 0.3f},
                 float spec = 0.5f) {
  PbrParams p;
  p.base_color = base;
  p.roughness = rough;
  p.metallic = metal;
  p.specular = spec;
  return p;
}

const Eigen::Vector3f kN(0, 0, 1);

// integral over the hemisphere of g(wi) by the midpoint rule in (cos theta, phi).
template <typename F>
double Hemisphere(const F& g, int n_theta = 300, int n_phi = 600) {
  double sum = 0;
  for (int i = 0; i < n_theta; ++i) {
    const double mu = (i + 0.5) / n_theta;
    for (int j = 0; j < n_phi; ++j) sum += g(Dir(std::acos(mu), (j + 0.5) * 2 * kPi / n_phi));
  }
  return sum * (2 * kPi) / (static_cast<double>(n_theta) * n_phi);
}

TEST(BsdfTest, LambertianLimit) {
  // no specular reflectance (F0 = 0) and v = l = n: f = rho / pi exactly.
  const Bsdf b(Params(1.0f, 0.0f, {0.6f, 0.4f, 0.2f}, 0.0f), kN, kN, kN);
  const Eigen::Vector3f f = b.Eval(kN);
  EXPECT_NEAR(f.x(), 0.6 / kPi, 1e-6);
  EXPECT_NEAR(f.y(), 0.4 / kPi, 1e-6);
  EXPECT_NEAR(f.z(), 0.2 / kPi, 1e-6);
  // at 60 degrees incidence the cosine halves it (Schlick's term at v.h = cos 30 deg is ~2e-5).
  EXPECT_NEAR(b.Eval(Dir(kPi / 3, 0.4)).x(), 0.5 * 0.6 / kPi, 1e-4);
}

TEST(BsdfTest, NothingBelowTheSurface) {
  const Bsdf b(Params(0.5f, 0.0f), kN, kN, Dir(0.3, 0));
  EXPECT_EQ(b.Eval(Dir(2.0, 1.0)).norm(), 0.0f);
  EXPECT_EQ(b.Pdf(Dir(2.0, 1.0)), 0.0f);
  // a shading normal tilted away from the viewer falls back to the geometric normal.
  const Eigen::Vector3f ns = Dir(1.4, kPi);
  const Bsdf c(Params(0.5f, 0.0f), ns, kN, Dir(1.2, 0));
  EXPECT_FLOAT_EQ(c.shading_normal().z(), 1.0f);
}

TEST(BsdfTest, Reciprocity) {
  Rng rng(7);
  for (int k = 0; k < 200; ++k) {
    const Eigen::Vector3f a = Dir(std::acos(rng.UniformD()), 2 * kPi * rng.UniformD());
    const Eigen::Vector3f c = Dir(std::acos(rng.UniformD()), 2 * kPi * rng.UniformD());
    const PbrParams p = Params(0.1f + 0.9f * rng.Uniform(), rng.Uniform());
    const Eigen::Vector3f fa = Bsdf(p, kN, kN, a).Eval(c) / c.z();
    const Eigen::Vector3f fc = Bsdf(p, kN, kN, c).Eval(a) / a.z();
    EXPECT_NEAR((fa - fc).norm() / std::max(1e-3f, fa.norm()), 0.0, 1e-3);
  }
}

TEST(BsdfTest, PdfIntegratesToOneAndEnergyIsConserved) {
  for (float rough : {0.3f, 0.6f, 1.0f}) {
    for (float metal : {0.0f, 1.0f}) {
      const Bsdf b(Params(rough, metal, {1, 1, 1}), kN, kN, Dir(0.5, 0.2));
      const double pdf_integral = Hemisphere([&](const Eigen::Vector3f& w) { return b.Pdf(w); });
      // visible normals reflected below the horizon are rejected, so the density integrates to
      // a little under 1 (much under 1 for rough metals, whose lobe is sampled alone).
      EXPECT_LT(pdf_integral, 1.005) << rough << " " << metal;
      EXPECT_GT(pdf_integral, metal > 0 ? 0.5 : 0.95) << rough << " " << metal;
      // a white surface reflects at most what it receives; single-scattering GGX loses energy
      // on rough metals (Heitz 2016, "Multiple-scattering microfacet BSDFs with the Smith model").
      const double albedo = Hemisphere([&](const Eigen::Vector3f& w) { return b.Eval(w).y(); });
      EXPECT_LT(albedo, 1.0) << rough << " " << metal;
      EXPECT_GT(albedo, metal > 0 ? 0.3 : 0.9) << rough << " " << metal;
    }
  }
}

TEST(BsdfTest, SampleAgreesWithEvalAndPdf) {
  Rng rng(11);
  for (float rough : {0.05f, 0.3f, 0.8f}) {
    for (float metal : {0.0f, 0.5f, 1.0f}) {
      const Bsdf b(Params(rough, metal), kN, kN, Dir(0.9, 1.0));
      int accepted = 0;
      for (int k = 0; k < 2000; ++k) {
        BsdfSample s;
        if (!b.Sample(rng.Uniform(), rng.Uniform(), rng.Uniform(), &s)) continue;
        ++accepted;
        EXPECT_NEAR(s.wi.norm(), 1.0f, 1e-5);
        EXPECT_EQ(s.pdf, b.Pdf(s.wi));
        EXPECT_EQ(s.f_cos, b.Eval(s.wi));
      }
      EXPECT_GT(accepted, 1000);  // rough metals reflect some visible normals below the horizon
    }
  }
}

TEST(BsdfTest, SamplingEstimatesTheReflectanceWithoutBias) {
  // E[f cos / pdf] over Sample() equals the quadrature of f cos over the hemisphere.
  for (float rough : {0.3f, 0.7f}) {
    for (float metal : {0.0f, 1.0f}) {
      const Bsdf b(Params(rough, metal), kN, kN, Dir(0.6, 2.0));
      const double reference = Hemisphere([&](const Eigen::Vector3f& w) { return b.Eval(w).x(); });
      Rng rng(3);
      const int n = 200000;
      double sum = 0;
      for (int k = 0; k < n; ++k) {
        BsdfSample s;
        if (b.Sample(rng.Uniform(), rng.Uniform(), rng.Uniform(), &s)) sum += s.f_cos.x() / s.pdf;
      }
      EXPECT_NEAR(sum / n, reference, 0.02 * reference) << rough << " " << metal;
    }
  }
}

TEST(BsdfTest, MetalsTintTheirReflectionDielectricsDoNot) {
  // at normal incidence the specular colour is F0: base colour for metals, 0.04 grey for
  // dielectrics (specular 0.5).
  const Bsdf metal(Params(0.5f, 1.0f, {0.9f, 0.5f, 0.1f}), kN, kN, kN);
  EXPECT_NEAR(metal.f0().x(), 0.9f, 1e-6);
  EXPECT_NEAR(metal.f0().z(), 0.1f, 1e-6);
  EXPECT_EQ(metal.diffuse_color().norm(), 0.0f);
  const Bsdf dielectric(Params(0.5f, 0.0f, {0.9f, 0.5f, 0.1f}), kN, kN, kN);
  EXPECT_NEAR(dielectric.f0().x(), 0.04f, 1e-6);
  EXPECT_NEAR(dielectric.f0().z(), 0.04f, 1e-6);
  EXPECT_NEAR(dielectric.diffuse_color().x(), 0.9f, 1e-6);
}

}  // namespace
}  // namespace penumbra
