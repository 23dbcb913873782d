#include "penumbra/environment/mjcf_builder.h"

#include <fmt/format.h>

#include <cmath>
#include <limits>
#include <map>

namespace penumbra {
namespace {

std::string Num(double v) {
  // 4 decimals, and never "-0.0000"
  std::string s = fmt::format("{:.4f}", v);
  if (s == "-0.0000") s = "0.0000";
  return s;
}

std::string Vec(const Eigen::Vector3d& v) {
  return Num(v.x()) + " " + Num(v.y()) + " " + Num(v.z());
}

// a cell index in a body name: "m3" for -3
std::string CellIndex(double v) {
  const long i = std::lround(std::floor(v / MjcfBuilder::kCellM));
  return i < 0 ? "m" + std::to_string(-i) : std::to_string(i);
}

}  // namespace

Eigen::Vector3d PlanFrame::Apply(const Eigen::Vector3d& p) const {
  const double c = std::cos(yaw_rad), s = std::sin(yaw_rad);
  return {origin.x() + c * p.x() - s * p.y(), origin.y() + s * p.x() + c * p.y(), p.z()};
}

void MjcfBuilder::AddMaterial(const std::string& name, const Eigen::Vector3d& rgb, double specular,
                              double shininess) {
  if (!material_names_.insert(name).second) return;
  materials_.push_back(
      fmt::format(R"(    <material name="{}" rgba="{} 1" specular="{}" shininess="{}"/>)", name,
                  Vec(rgb), Num(specular), Num(shininess)));
}

bool MjcfBuilder::HasMaterial(const std::string& name) const {
  return material_names_.count(name) > 0;
}

std::string MjcfBuilder::UniqueName(const std::string& name) {
  if (geom_names_.insert(name).second) return name;
  for (int n = 2;; ++n) {
    std::string candidate = name + "_" + std::to_string(n);
    if (geom_names_.insert(candidate).second) return candidate;
  }
}

std::string MjcfBuilder::AddGeom(const std::string& name, const std::string& type,
                                 const std::string& material, bool collide, GeomRecord g) {
  g.name = UniqueName(name);
  g.type = type;
  g.material = material;
  g.collide = collide;
  if (g.collide) ++colliding_;
  geoms_.push_back(std::move(g));
  return geoms_.back().name;
}

std::string MjcfBuilder::AddBox(const std::string& name, const PlanFrame& frame,
                                const Eigen::Vector3d& center, const Eigen::Vector3d& half,
                                const std::string& material, bool collide, double yaw_rad) {
  GeomRecord g;
  g.size = Vec(half);
  g.pos = frame.Apply(center);
  g.yaw_deg = std::remainder((frame.yaw_rad + yaw_rad) * 180.0 / M_PI, 360.0);
  if (std::abs(g.yaw_deg) < 1e-9) g.yaw_deg = 0;
  g.plan_half_extent = std::hypot(half.x(), half.y());
  return AddGeom(name, "box", material, collide, std::move(g));
}

std::string MjcfBuilder::AddCylinder(const std::string& name, const PlanFrame& frame,
                                     const Eigen::Vector3d& center, double radius,
                                     double half_height, const std::string& material,
                                     bool collide) {
  GeomRecord g;
  g.size = Num(radius) + " " + Num(half_height);
  g.pos = frame.Apply(center);
  g.plan_half_extent = radius;
  return AddGeom(name, "cylinder", material, collide, std::move(g));
}

std::string MjcfBuilder::AddSphere(const std::string& name, const PlanFrame& frame,
                                   const Eigen::Vector3d& center, double radius,
                                   const std::string& material, bool collide) {
  GeomRecord g;
  g.size = Num(radius);
  g.pos = frame.Apply(center);
  g.plan_half_extent = radius;
  return AddGeom(name, "sphere", material, collide, std::move(g));
}

std::string MjcfBuilder::AddPlane(const std::string& name, const Eigen::Vector3d& center, double hx,
                                  double hy, const std::string& material, bool collide) {
  GeomRecord g;
  g.size = Num(hx) + " " + Num(hy) + " 0.1";
  g.pos = center;
  g.plan_half_extent = std::numeric_limits<double>::infinity();
  return AddGeom(name, "plane", material, collide, std::move(g));
}

std::string MjcfBuilder::AddHeightField(const std::string& name, const std::string& file,
                                        const std::string& size, const Eigen::Vector3d& pos,
                                        const std::string& material, bool collide) {
  assets_.push_back(
      fmt::format(R"(    <hfield name="{}" file="{}" size="{}"/>)", name, file, size));
  GeomRecord g;
  g.hfield = name;
  g.pos = pos;
  g.plan_half_extent = std::numeric_limits<double>::infinity();
  return AddGeom(name, "hfield", material, collide, std::move(g));
}

std::string MjcfBuilder::BodyOf(const GeomRecord& g) const {
  if (g.plan_half_extent > kCellM / 2) return "";
  return "cell_" + CellIndex(g.pos.x()) + "_" + CellIndex(g.pos.y()) + (g.collide ? "" : "_visual");
}

int MjcfBuilder::bodies() const {
  std::set<std::string> names;
  for (const GeomRecord& g : geoms_) {
    const std::string b = BodyOf(g);
    if (!b.empty()) names.insert(b);
  }
  return static_cast<int>(names.size());
}

std::string MjcfBuilder::GeomXml(const GeomRecord& g, const Eigen::Vector3d& body_pos) {
  std::string s = g.hfield.empty()
                      ? fmt::format(R"(<geom name="{}" type="{}" size="{}" pos="{}")", g.name,
                                    g.type, g.size, Vec(g.pos - body_pos))
                      : fmt::format(R"(<geom name="{}" type="hfield" hfield="{}" pos="{}")", g.name,
                                    g.hfield, Vec(g.pos - body_pos));
  if (g.yaw_deg != 0) s += fmt::format(R"( euler="0 0 {}")", Num(g.yaw_deg));
  s += fmt::format(R"( material="{}")", g.material);
  if (!g.collide) s += R"( contype="0" conaffinity="0")";
  return s + "/>";
}

std::string MjcfBuilder::Xml(const std::string& model, const std::string& comment) const {
  std::string out = "<!--\n" + comment + "\n-->\n";
  out += fmt::format("<mujoco model=\"{}\">\n  <asset>\n", model);
  for (const std::string& a : assets_) out += a + "\n";
  for (const std::string& m : materials_) out += m + "\n";
  out += "  </asset>\n  <worldbody>\n";
  // the world body's geoms, then one static body per cell (name order), geoms in call order
  std::map<std::string, std::vector<const GeomRecord*>> cells;
  for (const GeomRecord& g : geoms_) {
    const std::string b = BodyOf(g);
    if (b.empty())
      out += "    " + GeomXml(g, Eigen::Vector3d::Zero()) + "\n";
    else
      cells[b].push_back(&g);
  }
  for (const auto& [name, geoms] : cells) {
    Eigen::Vector3d centre = Eigen::Vector3d::Zero();
    for (const GeomRecord* g : geoms) centre += g->pos;
    centre /= static_cast<double>(geoms.size());
    // round the body position to the written precision so the geoms' offsets add up exactly
    centre = Eigen::Vector3d(std::round(centre.x() * 1e4) / 1e4, std::round(centre.y() * 1e4) / 1e4,
                             std::round(centre.z() * 1e4) / 1e4);
    out += fmt::format("    <body name=\"{}\" pos=\"{}\">\n", name, Vec(centre));
    for (const GeomRecord* g : geoms) out += "      " + GeomXml(*g, centre) + "\n";
    out += "    </body>\n";
  }
  out += "  </worldbody>\n</mujoco>\n";
  return out;
}

}  // namespace penumbra
