#pragma once
// `penumbra heightfield WORLD`: the ground of a world (or the static geoms the user names)
// sampled from above with the renderer's ray queries (Embree) into a MuJoCo hfield model
// (render/geometry/height_field_sampling.h, assets/height_field_model.h, docs/environments.md
// "Height fields"): writes OUT/<name>.hfield and OUT/<name>.xml and prints which geoms it sampled,
// the grid and its error against the geometry at the cell centres.

#include <array>
#include <optional>
#include <string>
#include <vector>

#include "penumbra/scene/scene_description.h"

namespace penumbra {

/// options of `penumbra heightfield`.
struct HeightFieldOptions {
  std::string world_file;
  /// sample only this model's geoms ("" = any model's).
  std::string model;
  /// sample only static geoms whose composed name ("<model>/<geom>") matches one of these
  /// globs (core/text_match.h: '*' and '?'); empty = the default selection (HeightFieldGeoms).
  std::vector<std::string> geoms;
  /// sample every static geom (trees, rocks, furniture and walls included).
  bool all = false;
  double cell_m = 0.1;  ///< sample spacing, m
  /// plan rectangle x0, y0, x1, y1 (m); unset = the sampled geoms' bounds.
  std::optional<std::array<double, 4>> extent;
  std::string out_dir = ".";
  /// the files' stem; "" = the model's name, or "terrain".
  std::string name;
  double base_m = 0.1;  ///< MuJoCo hfield base thickness below the lowest sample, m
};

/// the glob patterns of the default selection: the ground, i.e. geoms named like a floor, the
/// ground or a terrain ("*floor*", "*ground*", "*terrain*", matched case-insensitively).
const std::vector<std::string>& GroundGeomGlobs();

/// the static geoms (`statics`: render/geometry/static_geometry.h StaticGeoms) a height field
/// samples:
///  - `all`: every one;
///  - else those of `model` (when set) whose name matches a glob of `geoms` (when set);
///  - with neither `model` nor `geoms` (the default): the ground, i.e. planes, height fields and
///    geoms whose composed name matches GroundGeomGlobs; not trees, rocks, furniture or walls.
/// @throws ConfigError naming the option (--model, --geoms, --all) when `model` is not a model
///         of `world_models`, when `all` is combined with a selection, or when the selection is
///         empty (the default's message names the patterns and the options that select more).
SceneDescription HeightFieldGeoms(const SceneDescription& statics,
                                  const std::vector<std::string>& world_models,
                                  const HeightFieldOptions& options);

/// samples and writes (file comment). returns 0.
/// @throws ConfigError for a bad world or selection (HeightFieldGeoms); Error when nothing is
///         sampled or files cannot be written.
int RunHeightField(const HeightFieldOptions& options);

}  // namespace penumbra
