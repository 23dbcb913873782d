// frames/s and rays/s of the Embree renderer on a synthetic furnished room: 6 x 5 x 3 m, walls,
// floor and ceiling, 6 tables (top, 4 legs, a mesh vase, a ball), 12 chairs (seat, back, 4
// capsule legs), 10 ellipsoids (all static bodies) and a mobile robot of 3 moving bodies that
// drives every frame: 137 geoms of every shape, 3 lights (2 soft point lights, 1 spot),
// rendered at 640 x 480 RGB + depth in the realtime tier.

#include <benchmark/benchmark.h>

#include <cmath>
#include <string>

#include "penumbra/core/pose.h"
#include "penumbra/render/backends/renderer_factory.h"
#include "penumbra/render/renderer.h"

namespace penumbra {
namespace {

Pose At(double x, double y, double z, double yaw = 0) {
  Pose X = Pose::Identity();
  X.linear() = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  X.translation() = Eigen::Vector3d(x, y, z);
  return X;
}

int AddMaterial(SceneDescription* s, Eigen::Vector3f c, float rough, float metal) {
  Material m;
  m.name = "m" + std::to_string(s->materials.size());
  m.base_color = c;
  m.roughness = rough;
  m.metallic = metal;
  s->materials.push_back(m);
  return static_cast<int>(s->materials.size()) - 1;
}

void Add(SceneDescription* s, int body, GeomShape shape, Eigen::Vector3d size, const Pose& X_BG,
         int material) {
  Geom g;
  g.id = static_cast<int>(s->geoms.size());
  g.name = "g" + std::to_string(g.id);
  g.body = body;
  g.shape = shape;
  g.size = size;
  g.X_BG = X_BG;
  g.material = material;
  s->geoms.push_back(g);
}

SceneDescription Room() {
  SceneDescription s;
  s.bodies.push_back({"world", -1, true});
  s.sky.radiance = {0.2f, 0.22f, 0.25f};
  // checker floor texture, 8 x 8.
  Texture tex;
  tex.name = "checker";
  std::vector<uint8_t> rgb;
  for (int i = 0; i < 64; ++i) {
    const uint8_t c = ((i % 8) + (i / 8)) % 2 ? 200 : 90;
    rgb.insert(rgb.end(), {c, c, c});
  }
  tex.image = std::make_shared<const TextureImage>(8, 8, 1, std::move(rgb));
  s.textures.push_back(tex);
  const int floor = AddMaterial(&s, {0.9f, 0.85f, 0.8f}, 0.7f, 0);
  s.materials[floor].texture = 0;
  s.materials[floor].texuniform = true;
  const int wall = AddMaterial(&s, {0.8f, 0.8f, 0.75f}, 0.9f, 0);
  const int wood = AddMaterial(&s, {0.5f, 0.3f, 0.15f}, 0.5f, 0);
  const int metal = AddMaterial(&s, {0.9f, 0.9f, 0.9f}, 0.3f, 1);
  const int fabric = AddMaterial(&s, {0.2f, 0.3f, 0.6f}, 0.9f, 0);
  const int plastic = AddMaterial(&s, {0.8f, 0.2f, 0.1f}, 0.4f, 0);

  const double W = 3.0, D = 2.5, H = 3.0;  // half width (x), half depth (y), height
  Add(&s, 0, GeomShape::kPlane, {0, 0, 1}, At(0, 0, 0), floor);
  Add(&s, 0, GeomShape::kBox, {W, D, 0.05}, At(0, 0, H + 0.05), wall);
  Add(&s, 0, GeomShape::kBox, {0.05, D, H / 2}, At(W + 0.05, 0, H / 2), wall);
  Add(&s, 0, GeomShape::kBox, {0.05, D, H / 2}, At(-W - 0.05, 0, H / 2), wall);
  Add(&s, 0, GeomShape::kBox, {W, 0.05, H / 2}, At(0, D + 0.05, H / 2), wall);
  Add(&s, 0, GeomShape::kBox, {W, 0.05, H / 2}, At(0, -D - 0.05, H / 2), wall);

  // a low-poly mesh (octahedron) for vases.
  TriangleMesh oct;
  oct.name = "octahedron";
  oct.vertices = {{0.1f, 0, 0},  {-0.1f, 0, 0}, {0, 0.1f, 0},
                  {0, -0.1f, 0}, {0, 0, 0.15f}, {0, 0, -0.15f}};
  oct.faces = {{0, 2, 4}, {2, 1, 4}, {1, 3, 4}, {3, 0, 4},
               {2, 0, 5}, {1, 2, 5}, {3, 1, 5}, {0, 3, 5}};
  s.meshes.push_back(oct);

  // six tables on a 3 x 2 grid, each with a chair on either side (along x, backrests away from
  // the table); each table and chair is its own static body, its geoms placed in the world.
  int n = 0;
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 2; ++j, ++n) {
      const double x = -1.8 + 1.8 * i, y = -1.2 + 2.4 * j;
      s.bodies.push_back({"table" + std::to_string(n), 0, true});
      const int tb = static_cast<int>(s.bodies.size()) - 1;
      Add(&s, tb, GeomShape::kBox, {0.4, 0.3, 0.02}, At(x, y, 0.72), wood);
      for (int k = 0; k < 4; ++k)
        Add(&s, tb, GeomShape::kCylinder, {0.025, 0.35, 0},
            At(x + (k & 1 ? 0.35 : -0.35), y + (k & 2 ? 0.25 : -0.25), 0.35), metal);
      Add(&s, tb, GeomShape::kMesh, {0, 0, 0}, At(x + 0.1, y + 0.05, 0.89), plastic);
      s.geoms.back().mesh = 0;
      Add(&s, tb, GeomShape::kSphere, {0.06, 0, 0}, At(x - 0.2, y - 0.1, 0.8), metal);
      for (int c = 0; c < 2; ++c) {
        s.bodies.push_back({"chair" + std::to_string(2 * n + c), 0, true});
        const int cb = static_cast<int>(s.bodies.size()) - 1;
        const double side = c ? 1 : -1;
        const double cx = x + side * 0.6;
        Add(&s, cb, GeomShape::kBox, {0.2, 0.2, 0.02}, At(cx, y, 0.45), fabric);
        Add(&s, cb, GeomShape::kBox, {0.02, 0.2, 0.22}, At(cx + side * 0.2, y, 0.69), fabric);
        for (int k = 0; k < 4; ++k)
          Add(&s, cb, GeomShape::kCapsule, {0.015, 0.2, 0},
              At(cx + (k & 1 ? 0.17 : -0.17), y + (k & 2 ? 0.17 : -0.17), 0.22), metal);
      }
    }
  }
  // a mobile robot (3 moving bodies: base, mast, head) that drives around every frame.
  s.bodies.push_back({"robot_base", 0, false});
  const int rb = static_cast<int>(s.bodies.size()) - 1;
  Add(&s, rb, GeomShape::kCylinder, {0.25, 0.1, 0}, At(0, 0, 0.15), plastic);
  for (int k = 0; k < 4; ++k)
    Add(&s, rb, GeomShape::kSphere, {0.05, 0, 0},
        At(k & 1 ? 0.18 : -0.18, k & 2 ? 0.18 : -0.18, 0.05), metal);
  s.bodies.push_back({"robot_mast", rb, false});
  Add(&s, static_cast<int>(s.bodies.size()) - 1, GeomShape::kCapsule, {0.04, 0.4, 0},
      At(0, 0, 0.65), metal);
  s.bodies.push_back({"robot_head", static_cast<int>(s.bodies.size()) - 1, false});
  Add(&s, static_cast<int>(s.bodies.size()) - 1, GeomShape::kBox, {0.1, 0.15, 0.08}, At(0, 0, 1.15),
      plastic);
  // a shelf of balls along one wall.
  for (int k = 0; k < 10; ++k)
    Add(&s, 0, GeomShape::kEllipsoid, {0.08, 0.06, 0.1}, At(-2.7 + 0.6 * k, 2.3, 1.2), plastic);

  Light a;
  a.type = Light::Type::kPoint;
  a.position_B = {-1.2, 0, 2.7};
  a.intensity = 400;
  a.radius_m = 0.05;
  s.lights.push_back(a);
  Light b = a;
  b.position_B = {1.2, 0, 2.7};
  s.lights.push_back(b);
  Light spot;
  spot.type = Light::Type::kSpot;
  spot.position_B = {2.5, -2.0, 2.5};
  spot.direction_B = Eigen::Vector3d(-1, 1, -1).normalized();
  spot.intensity = 1500;
  spot.spot_inner_deg = 20;
  spot.spot_outer_deg = 35;
  s.lights.push_back(spot);
  return s;
}

void BM_RenderRoom(benchmark::State& state) {
  const SceneDescription scene = Room();
  RenderSettings settings;
  settings.tier = RenderSettings::Tier::kRealtime;
  settings.threads = static_cast<int>(state.range(0));
  auto renderer = MakeRenderer(scene, settings);
  WorldSnapshot snap;
  snap.X_WB.assign(scene.bodies.size(), Pose::Identity());
  const int robot = scene.FindBody("robot_base");
  CameraView view;
  // REP-103 camera body in a corner, 1.6 m up, looking at the room centre, pitched down.
  const Pose X_WC = PoseFromXyzRpyDeg({-2.8, -2.3, 1.6}, {0, 20, 40});
  view.X_WO = X_WC * Pose(RotationBodyFromOptical());
  view.intrinsics = CameraIntrinsics::FromFovy(640, 480, 60);
  view.outputs[ImageKind::kRgb] = true;
  view.outputs[ImageKind::kDepth] = true;
  RenderedFrame frame;
  int64_t rays = 0;
  for (auto _ : state) {
    // the robot drives in a circle, as in a simulation.
    const double a = 0.05 * static_cast<double>(view.frame_index);
    const Pose X_base = At(1.2 * std::cos(a), 1.2 * std::sin(a), 0, a + M_PI / 2);
    snap.X_WB[robot] = X_base;
    snap.X_WB[robot + 1] = X_base;
    snap.X_WB[robot + 2] = X_base * At(0, 0, 0, 0.3 * std::sin(3 * a));
    renderer->Render(snap, view, &frame);
    rays += frame.rays;
    ++view.frame_index;
  }
  state.counters["frames/s"] =
      benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
  state.counters["Mrays/s"] = benchmark::Counter(rays * 1e-6, benchmark::Counter::kIsRate);
  state.counters["geoms"] = static_cast<double>(scene.geoms.size());
}
BENCHMARK(BM_RenderRoom)
    ->Arg(1)
    ->Arg(2)
    ->Unit(benchmark::kMillisecond)
    ->MeasureProcessCPUTime()  // CPU column: all threads, comparable on a busy machine
    ->UseRealTime();

}  // namespace
}  // namespace penumbra
