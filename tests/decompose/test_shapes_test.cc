#include "penumbra/decompose/test_shapes.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "penumbra/core/error.h"

namespace penumbra {
namespace {

TEST(TestShapes, ClosedAndOutwardWithTheExpectedVolume) {
  const double pi = std::numbers::pi;
  struct Case {
    std::string name;
    double volume;
    double tolerance;
  } cases[] = {
      {"l", (1.0 * 0.4 + 0.4 * 0.6) * 0.4, 1e-12},
      {"u", (1.0 * 0.3 + 2 * 0.3 * 0.7) * 0.4, 1e-12},
      {"torus", 2 * pi * pi * 0.35 * 0.12 * 0.12, 0.05},    // polygonal: a little less
      {"bowl", 2.0 / 3.0 * pi * (0.125 - 0.091125), 0.05},  // 2/3 pi (R^3 - r^3)
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    const SolidMesh mesh = MakeTestShape(c.name);
    EXPECT_NO_THROW(ValidateClosedMesh(mesh, c.name));
    EXPECT_NEAR(MeshVolume(mesh), c.volume, c.tolerance * c.volume);
  }
}

TEST(TestShapes, OpenOrInvertedMeshesAreRejectedWithTheProblem) {
  SolidMesh open = MakeLShape();
  open.triangles.pop_back();
  try {
    ValidateClosedMesh(open, "open.obj");
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("open.obj"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("watertight"), std::string::npos) << e.what();
  }
  SolidMesh inverted = MakeLShape();
  for (auto& t : inverted.triangles) std::swap(t[1], t[2]);
  try {
    ValidateClosedMesh(inverted, "inverted.obj");
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("outward"), std::string::npos) << e.what();
  }
  EXPECT_THROW(MakeTestShape("teapot"), Error);
}

}  // namespace
}  // namespace penumbra
