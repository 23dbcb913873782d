#pragma once
// reads a float density grid from an OpenVDB file (OpenVDB 10, https://www.openvdb.org)
// into a dense GridMedium (scene/effects_frame.h).

#include <optional>
#include <string>

#include "penumbra/effects/types/vdb_smoke.h"
#include "penumbra/scene/effects_frame.h"

namespace penumbra {

/// loads grid `p.grid` of `p.file` and resamples it trilinearly (openvdb::tools::BoxSampler)
/// at the voxel centres of a dense grid: the grid's active voxel bounding box (index
/// bounds +- half a voxel, through the file's transform to metres) is covered by
/// dims x min(1, max_resolution / max dim) voxels per axis (at least 1), so a grid within
/// max_resolution is copied voxel for voxel. placement: `region` given -> the box is
/// stretched to fill it; else the file's world coordinates. medium coefficients from p
/// (sigma_t = density_scale_per_m per channel, albedo, g); density values are clamped to >= 0.
/// @param key_prefix key path of the effect in errors, e.g. "effects[3]"
/// @param effect_name named in error messages
/// @throws ConfigError("", 0, "<prefix>.file", ...) when the file cannot be opened
///         or is not a VDB file, and ("<prefix>.grid", ...) when it has no float grid
///         of that name (the message lists the grids it has) or the grid has no active voxels.
GridMedium LoadVdbDensity(const VdbSmokeParams& p, const std::optional<BoxRegion>& region,
                          const std::string& key_prefix, const std::string& effect_name);

}  // namespace penumbra
