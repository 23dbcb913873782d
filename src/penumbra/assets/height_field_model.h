#pragma once
// a height field (render/geometry/height_field_sampling.h) as MuJoCo reads it: the custom binary
// hfield file (MuJoCo XML reference, <hfield file>: "int32 nrow, int32 ncol, float32
// data[nrow*ncol]", row-major, row 0 at -size_y) and an MJCF model of one hfield geom that
// reproduces the samples: elevations normalised to [0, 1], size = (half extent x, half extent
// y, z_max - z_min, base), the geom at the grid's centre and at z_min.

#include <string>

#include "penumbra/render/geometry/height_field_sampling.h"

namespace penumbra {

/// the binary hfield file of `field` (values normalised to [0, 1] by its min and max).
std::string HfieldFileBytes(const SampledHeightField& field);

/// an MJCF model `model` with the hfield asset "terrain" (file `hfield_file`, absolute) and
/// the geom "terrain" (material "terrain" of `rgb`, sRGB; base_m below the lowest sample).
/// a field with no relief (max = min) gets a range of 1 mm.
std::string HeightFieldMjcf(const std::string& model, const SampledHeightField& field,
                            const std::string& hfield_file, double base_m,
                            const Eigen::Vector3d& rgb);

/// the hfield asset attributes of `field` (without the name and file): `nrow`, `ncol` are read
/// from the file; this is `size="sx sy sz base"`.
std::string HfieldSizeAttribute(const SampledHeightField& field, double base_m);
/// the position of the hfield geom reproducing `field`: grid centre, z_min.
Eigen::Vector3d HfieldGeomPosition(const SampledHeightField& field);

}  // namespace penumbra
