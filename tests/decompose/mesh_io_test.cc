// ReadMeshFile: OBJ and OFF files of a closed solid come back closed, with the file's volume
// times scale^3; missing and empty files are errors naming the path.
#include "penumbra/decompose/mesh_io.h"

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <string>

#include "common/temp_dir.h"
#include "penumbra/core/error.h"
#include "penumbra/decompose/solid_mesh.h"
#include "penumbra/decompose/test_shapes.h"

namespace penumbra {
namespace {

TEST(MeshIo, ObjAndOffOfAClosedSolidReadBackClosedWithTheirVolume) {
  const SolidMesh u = MakeUShape();
  std::string obj, off = fmt::format("OFF\n{} {} 0\n", u.vertices.size(), u.triangles.size());
  for (const Eigen::Vector3d& v : u.vertices) {
    obj += fmt::format("v {:.17g} {:.17g} {:.17g}\n", v.x(), v.y(), v.z());
    off += fmt::format("{:.17g} {:.17g} {:.17g}\n", v.x(), v.y(), v.z());
  }
  for (const auto& t : u.triangles) {
    obj += fmt::format("f {} {} {}\n", t[0] + 1, t[1] + 1, t[2] + 1);
    off += fmt::format("3 {} {} {}\n", t[0], t[1], t[2]);
  }
  testing::TempDir dir;
  for (const std::string& name : {std::string("u.obj"), std::string("u.off")}) {
    const std::string path = dir.Write(name, name == "u.obj" ? obj : off);
    const SolidMesh m = ReadMeshFile(path, 0.01);  // centimetres
    EXPECT_NO_THROW(ValidateClosedMesh(m, name));
    EXPECT_EQ(m.vertices.size(), u.vertices.size()) << name;
    EXPECT_NEAR(MeshVolume(m), MeshVolume(u) * 1e-6, 1e-12) << name;
  }
  for (const std::string& bad :
       {(dir.path() / "missing.obj").string(), dir.Write("empty.obj", "# nothing\n")}) {
    try {
      ReadMeshFile(bad);
      ADD_FAILURE() << "no error for " << bad;
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(bad), std::string::npos) << e.what();
    }
  }
}

}  // namespace
}  // namespace penumbra
