#pragma once
// the MJCF text of a generated environment: materials and static primitive geoms (MuJoCo
// XML reference: <material>, <geom type="box|cylinder|sphere|plane">). geoms made with
// `collide = false` are visual only (contype = conaffinity = 0), the rest collide with the
// robots. numbers are written with 4 decimals (0.1 mm), so the text is a pure function of the
// calls.
//
// bodies: MuJoCo 2.2.2 tested every geom of the world body against every moving body in each
// step (the world body has no bounding sphere to prune with), which made a warehouse of 1157
// world-body geoms step 9x slower than the default room (measured on 2.2.2). so Xml() keeps only planes and large
// geoms (plan half extent > kCellM / 2: walls, floors, the ceiling) in the world body and puts
// the rest into static bodies, one per kCellM x kCellM plan cell and kind (colliding or visual),
// "cell_<i>_<j>" / "cell_<i>_<j>_visual", each placed at the mean of its geoms' centres. the
// broad phase then skips every cell away from a robot, and static bodies are never collided
// with each other (no joints: welded to the world); the renderer merges them into its static
// scene like the world body.

#include <Eigen/Core>
#include <set>
#include <string>
#include <vector>

namespace penumbra {

/// a pose in the plan: the frame's origin (x, y) in the model frame, m, and its yaw about +z,
/// rad. used to place furniture built in its own frame (x along its front, y into the room).
struct PlanFrame {
  Eigen::Vector2d origin{0, 0};
  double yaw_rad = 0;
  /// the model-frame point of the local point `p` (m).
  Eigen::Vector3d Apply(const Eigen::Vector3d& p) const;
};

/// collects materials and geoms and writes them as one MJCF model.
class MjcfBuilder {
 public:
  /// side of the plan cells that group small geoms into static bodies, m.
  static constexpr double kCellM = 4.0;

  /// a material; `rgb` is sRGB in [0, 1] (MuJoCo's rgba), specular / shininess as MuJoCo's
  /// (0 ... 1). a second material of the same name is ignored (the first one stays).
  void AddMaterial(const std::string& name, const Eigen::Vector3d& rgb, double specular = 0.3,
                   double shininess = 0.1);
  /// true when a material of that name was added.
  bool HasMaterial(const std::string& name) const;

  /// a box of half sizes `half` (m) centred at the local point `center` of `frame`, turned by
  /// the frame's yaw plus `yaw_rad`. the name is `name`, or `name_<n>` when that is taken.
  /// @returns the geom's name.
  std::string AddBox(const std::string& name, const PlanFrame& frame, const Eigen::Vector3d& center,
                     const Eigen::Vector3d& half, const std::string& material, bool collide,
                     double yaw_rad = 0);
  /// a z-aligned cylinder of `radius` and half height `half_height` centred at `center`.
  std::string AddCylinder(const std::string& name, const PlanFrame& frame,
                          const Eigen::Vector3d& center, double radius, double half_height,
                          const std::string& material, bool collide);
  /// a sphere.
  std::string AddSphere(const std::string& name, const PlanFrame& frame,
                        const Eigen::Vector3d& center, double radius, const std::string& material,
                        bool collide);
  /// an infinite plane at height z for collisions, drawn over half extents (hx, hy) around (x, y).
  std::string AddPlane(const std::string& name, const Eigen::Vector3d& center, double hx, double hy,
                       const std::string& material, bool collide);

  /// a MuJoCo hfield asset `name` (MuJoCo's binary file `file`, `size` "sx sy sz base") and
  /// its geom at `pos` (model frame), in the world body.
  std::string AddHeightField(const std::string& name, const std::string& file,
                             const std::string& size, const Eigen::Vector3d& pos,
                             const std::string& material, bool collide);

  /// number of geoms, and of those that collide.
  int geoms() const { return static_cast<int>(geoms_.size()); }
  int colliding_geoms() const { return colliding_; }
  /// number of static bodies Xml() writes (cells with geoms).
  int bodies() const;

  /// the whole MJCF document: `<mujoco model="model">` with `comment` (may be multi-line) as an
  /// XML comment at the top.
  std::string Xml(const std::string& model, const std::string& comment) const;

 private:
  struct GeomRecord {
    std::string name, type, size, material;
    std::string hfield;            ///< the hfield asset of an hfield geom
    Eigen::Vector3d pos{0, 0, 0};  ///< model frame, m
    double yaw_deg = 0;
    double plan_half_extent = 0;  ///< largest plan half extent, m (planes: infinite)
    bool collide = true;
  };
  std::string UniqueName(const std::string& name);
  /// keeps `g` (its shape fields set) as a geom of `type` named UniqueName(name), with
  /// `material` and `collide`; returns the name.
  std::string AddGeom(const std::string& name, const std::string& type, const std::string& material,
                      bool collide, GeomRecord g);
  /// the body of `g`: "" = the world body.
  std::string BodyOf(const GeomRecord& g) const;
  static std::string GeomXml(const GeomRecord& g, const Eigen::Vector3d& body_pos);

  std::vector<std::string> materials_, assets_;
  std::vector<GeomRecord> geoms_;
  std::set<std::string> material_names_, geom_names_;
  int colliding_ = 0;
};

}  // namespace penumbra
