#pragma once
// `penumbra heightfield WORLD`: a world's static geometry (or one model's) sampled from above
// with the renderer's ray queries (Embree) into a MuJoCo hfield model (render/
// height_field_sampling.h, assets/height_field_model.h, docs/environments.md "Height
// fields"): writes OUT/<name>.hfield and OUT/<name>.xml and prints the grid and its error
// against the geometry at the cell centres.

#include <array>
#include <optional>
#include <string>

namespace penumbra {

/// options of `penumbra heightfield`.
struct HeightFieldOptions {
  std::string world_file;
  /// sample only this model's geoms ("" = every static geom of the world).
  std::string model;
  double cell_m = 0.1;  ///< sample spacing, m
  /// plan rectangle x0, y0, x1, y1 (m); unset = the sampled geoms' bounds.
  std::optional<std::array<double, 4>> extent;
  std::string out_dir = ".";
  /// the files' stem; "" = the model's name, or "terrain".
  std::string name;
  double base_m = 0.1;  ///< MuJoCo hfield base thickness below the lowest sample, m
};

/// samples and writes (file comment). returns 0.
/// @throws ConfigError for a bad world or an unknown model; Error when nothing is sampled or
///         files cannot be written.
int RunHeightField(const HeightFieldOptions& options);

}  // namespace penumbra
