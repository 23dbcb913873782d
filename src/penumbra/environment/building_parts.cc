#include "penumbra/environment/building_parts.h"

#include <algorithm>
#include <cmath>

namespace penumbra {

void AddWall(MjcfBuilder* b, const std::string& name, const Eigen::Vector2d& a,
             const Eigen::Vector2d& bp, const std::vector<WallOpening>& openings,
             const WallStyle& style) {
  const Eigen::Vector2d d = bp - a;
  const double length = d.norm();
  const PlanFrame f{a, std::atan2(d.y(), d.x())};
  const double ht = style.thickness_m / 2, h = style.height_m;
  std::vector<WallOpening> sorted = openings;
  std::sort(sorted.begin(), sorted.end(),
            [](const WallOpening& x, const WallOpening& y) { return x.center_m < y.center_m; });
  // a solid piece from s0 to s1, z0 to z1
  const auto piece = [&](const std::string& part, double s0, double s1, double z0, double z1) {
    if (s1 - s0 < 1e-4 || z1 - z0 < 1e-4) return;
    b->AddBox(name + "_" + part, f, {(s0 + s1) / 2, 0, (z0 + z1) / 2},
              {(s1 - s0) / 2, ht, (z1 - z0) / 2}, style.wall, true);
  };
  double s = 0;
  for (const WallOpening& o : sorted) {
    const double s0 = o.center_m - o.width_m / 2, s1 = o.center_m + o.width_m / 2;
    piece("solid", s, s0, 0, h);
    piece("sill", s0, s1, 0, o.bottom_m);
    piece("lintel", s0, s1, o.top_m, h);
    s = s1;
    // the frame: two jambs, a head, and for a window a bottom and a cross mullion
    const double fw = 0.025, fd = ht + 0.01;
    const auto trim = [&](const std::string& part, double cx, double cz, double hx, double hz) {
      b->AddBox(name + "_" + part, f, {cx, 0, cz}, {hx, fd, hz}, style.frame, false);
    };
    const double zc = (o.bottom_m + o.top_m) / 2, hz = (o.top_m - o.bottom_m) / 2;
    trim("jamb", s0 + fw, zc, fw, hz);
    trim("jamb", s1 - fw, zc, fw, hz);
    trim("head", o.center_m, o.top_m - fw, o.width_m / 2, fw);
    if (o.bottom_m > 0) {
      trim("sill_trim", o.center_m, o.bottom_m + fw, o.width_m / 2, fw);
      b->AddBox(name + "_mullion", f, {o.center_m, 0, zc}, {0.02, 0.02, hz}, style.frame, false);
      b->AddBox(name + "_transom", f, {o.center_m, 0, zc + hz * 0.3}, {o.width_m / 2, 0.02, 0.02},
                style.frame, false);
    }
  }
  piece("solid", s, length, 0, h);
}

LightConfig AddCeilingLamp(MjcfBuilder* b, const std::string& name, double x, double y,
                           double ceiling_z, double drop_m, double radius_m, double intensity_cd,
                           const std::string& housing_material,
                           const std::string& diffuser_material) {
  const PlanFrame f{{x, y}, 0};
  const double underside = ceiling_z - drop_m;
  b->AddCylinder(name + "_stem", f, {0, 0, (ceiling_z + underside + 0.04) / 2}, 0.008,
                 (ceiling_z - underside - 0.04) / 2, housing_material, false);
  b->AddCylinder(name + "_housing", f, {0, 0, underside + 0.025}, radius_m + 0.02, 0.015,
                 housing_material, false);
  b->AddCylinder(name + "_diffuser", f, {0, 0, underside + 0.005}, radius_m, 0.005,
                 diffuser_material, false);
  LightConfig l;
  l.name = name;
  l.type = Light::Type::kPoint;
  l.position = {x, y, underside - 0.07};
  l.color = {1.0f, 0.9f, 0.78f};
  l.intensity_cd = intensity_cd;
  l.radius_m = 0.05;
  return l;
}

void AddProceduralMaterial(MjcfBuilder* b, std::vector<ProceduralMaterialEntry>* out,
                           const std::string& name, const std::string& type, uint64_t seed,
                           std::optional<Eigen::Vector3f> color, double size_m, int resolution,
                           const Eigen::Vector3d& preview_rgb) {
  b->AddMaterial(name, preview_rgb, 0.3, 0.1);
  ProceduralMaterialEntry e;
  e.material = name;
  e.config.type = type;
  e.config.seed = seed;
  e.config.color = color;
  e.config.size_m = size_m;
  e.config.resolution = resolution;
  out->push_back(std::move(e));
}

void EnvironmentBuilder::Procedural(const std::string& name, const std::string& type, uint64_t seed,
                                    std::optional<Eigen::Vector3f> color, double size_m,
                                    const Eigen::Vector3d& preview_rgb) {
  AddProceduralMaterial(&b_, &out_.materials, name, type, seed, color, size_m, resolution_,
                        preview_rgb);
}

GeneratedEnvironment EnvironmentBuilder::Finish(const PlanLayout& layout, const std::string& model,
                                                const std::string& comment) {
  out_.walkways = layout.walkways();
  out_.geoms = b_.geoms();
  out_.colliding_geoms = b_.colliding_geoms();
  out_.mjcf = b_.Xml(model, comment);
  return std::move(out_);
}

double AddCartonStack(MjcfBuilder* b, PlanRandom* rnd, const std::string& name,
                      const PlanFrame& frame, double w, double d, double z0, int max_layers,
                      double max_height_m, const std::string& material, bool collide) {
  const int layers = rnd->Int(1, max_layers);
  double z = z0;
  for (int layer = 0; layer < layers; ++layer) {
    const double h = rnd->Uniform(0.2, 0.4);
    if (z + h - z0 > max_height_m) break;
    // a row of 1-3 cartons across the width, each 85-98 % of its share
    const int n = rnd->Int(1, 3);
    const double share = w / n;
    for (int i = 0; i < n; ++i) {
      if (layer > 0 && rnd->Chance(0.25)) continue;  // a gap in an upper layer
      const double bw = share * rnd->Uniform(0.85, 0.98) / 2;
      const double bd = d * rnd->Uniform(0.8, 0.97) / 2;
      const double cx = -w / 2 + share * (i + 0.5);
      b->AddBox(name + "_carton", frame, {cx, d / 2, z + h / 2}, {bw, bd, h / 2}, material, collide,
                rnd->Uniform(-0.06, 0.06));
    }
    z += h;
  }
  return z;
}

}  // namespace penumbra
