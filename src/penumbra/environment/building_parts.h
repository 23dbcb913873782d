#pragma once
// parts shared by the generated buildings: walls with door and window openings, ceiling
// lamps, stacks of cartons.

#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

#include "penumbra/environment/mjcf_builder.h"
#include "penumbra/environment/plan_layout.h"
#include "penumbra/world/world_config.h"

namespace penumbra {

/// an opening in a wall: along the wall from its start point, m; from `bottom_m` to `top_m`
/// above the floor. a window (bottom > 0) gets a frame and a cross mullion, a door a frame.
struct WallOpening {
  double center_m = 0, width_m = 1;
  double bottom_m = 0, top_m = 2.1;
};

/// materials of a wall's parts.
struct WallStyle {
  std::string wall;   ///< the wall's surface
  std::string frame;  ///< door and window frames (visual only)
  double thickness_m = 0.12, height_m = 2.7;
};

/// an axis-aligned or slanted straight wall from `a` to `b` (plan, m; the wall's centre line)
/// with `openings`: solid boxes between the openings, a sill below and a lintel above each,
/// frames (5 cm, visual only) around them. the wall boxes collide. names "<name>_..".
void AddWall(MjcfBuilder* b, const std::string& name, const Eigen::Vector2d& a,
             const Eigen::Vector2d& bp, const std::vector<WallOpening>& openings,
             const WallStyle& style);

/// a ceiling lamp hanging at (x, y) under a ceiling at `ceiling_z`: a housing and a diffuser
/// (visual geoms "<name>_housing", "<name>_diffuser", the diffuser's underside
/// `drop_m` below the ceiling) and the point light of `intensity_cd` 7 cm below it (returned,
/// model frame, warm white). the diffuser is not emissive: the point light is the source (an
/// emissive diffuser as well would count twice in the pathtraced tier).
LightConfig AddCeilingLamp(MjcfBuilder* b, const std::string& name, double x, double y,
                           double ceiling_z, double drop_m, double radius_m, double intensity_cd,
                           const std::string& housing_material,
                           const std::string& diffuser_material);

/// a procedural material (assets/procedural_material.h) named `name`: its MJCF material (plain
/// `preview_rgb`, sRGB, for viewers that do not read the maps) and its entry in *out.
void AddProceduralMaterial(MjcfBuilder* b, std::vector<ProceduralMaterialEntry>* out,
                           const std::string& name, const std::string& type, uint64_t seed,
                           std::optional<Eigen::Vector3f> color, double size_m, int resolution,
                           const Eigen::Vector3d& preview_rgb);

/// what the generators (house, warehouse, outdoor) share: the MJCF being built, the result,
/// the resolution of the procedural maps.
class EnvironmentBuilder {
 protected:
  explicit EnvironmentBuilder(int texture_resolution) : resolution_(texture_resolution) {}

  /// AddProceduralMaterial at this builder's resolution.
  void Procedural(const std::string& name, const std::string& type, uint64_t seed,
                  std::optional<Eigen::Vector3f> color, double size_m,
                  const Eigen::Vector3d& preview_rgb);
  /// the result: the walkways of `layout`, the geom counts, the MJCF of model `model`.
  GeneratedEnvironment Finish(const PlanLayout& layout, const std::string& model,
                              const std::string& comment);

  MjcfBuilder b_;
  GeneratedEnvironment out_;
  int resolution_;
};

/// a stack of 1 ... `max_layers` cartons on the local rectangle [-w/2, w/2] x [0, d] of
/// `frame` starting at height z0 (m): each layer a random count of cartons with random sizes
/// that fit the rectangle, slightly turned. returns the stack's top height. `collide` for the
/// boxes.
double AddCartonStack(MjcfBuilder* b, PlanRandom* rnd, const std::string& name,
                      const PlanFrame& frame, double w, double d, double z0, int max_layers,
                      double max_height_m, const std::string& material, bool collide);

}  // namespace penumbra
