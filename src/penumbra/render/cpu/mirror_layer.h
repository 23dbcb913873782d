#pragma once
// the realtime tier's mirror layer (SurfaceMaterial::mirror, weight r): a pixel's radiance L
// becomes (1 - r) L + r L_m, L_m the radiance arriving along the camera ray mirrored about the
// surface's geometric normal (MirrorRadiance: the sky where it escapes, else the surface it
// hits shaded as the tier shades what the camera sees, one sample of every light with a
// shadow ray).
//
// importance: L_m costs more than the pixel's own shading (it is traced and shaded
// one pixel at a time), so a 5 % floor traced at every pixel cost 2.4-2.9x the frame. the
// layer is sampled by its weight: pixels with r >= kMirrorDenseReflectance (real mirrors,
// polished metal) trace their own L_m, as before; below it L_m is traced on a grid of every
// 2nd pixel in u and v (r >= kMirrorHalfStepReflectance: a quarter of the pixels) or every 4th
// (weaker: a sixteenth), global u and v (tiles start at multiples of 16), and every other pixel
// of the layer takes the bilinear interpolation of the traced L_m of the grid pixels around it
// that lie in the same tile, on the same grid and on the same flat face (same geom, bitwise
// equal geometric normal), the weights renormalised over those; a pixel with none traces its
// own. the error is r |L_m,interp - L_m|, at most r times the reflected contrast across the
// grid step: reflected edges are softened over 2 or 4 pixels (a 5 % floor: 1/20 of the
// reflected contrast). the reflection's random numbers are as before (draws num_lights ... of
// the traced pixel's stream), so the dense layer is bit-identical to the per-pixel one, and so
// is the whole image of a scene without weak mirrors.
// the arithmetic is the transport's (render/transport/realtime_mirror.h: MirroredRay,
// MirrorHitRadiance, MirrorGridLenders, MirrorGridMean, MirrorLayerBlend), shared with the CUDA
// backend; this file is the CPU's driver: the tile loop, Embree's rays and the CPU's surface
// evaluation. RenderAblation::mirror_sparse = false traces every pixel (bench comparisons).
//
// determinism: per tile, independent of thread count and tile order.

#include <Eigen/Core>
#include <cstdint>

#include "penumbra/render/cpu/integrator.h"
#include "penumbra/render/light/mirror_math.h"

namespace penumbra {

/// radiance arriving along the mirrored ray `ray` (see the file comment): the sky's
/// Background where it escapes, else the transport's MirrorHitRadiance at the hit (its light
/// samples' numbers from draws lights->size() ... of the pixel's `stream`; shadow rays through
/// Embree and the sun-occluder map). `path_m`: the camera-to-mirror distance (texture level of
/// detail); `wetness`: MediaFrame::surface_wetness; no media or particles along the ray. adds
/// the rays it traces to *traced.
Eigen::Vector3f MirrorRadiance(const FrameContext& ctx, const Ray& ray, float path_m, float wetness,
                               uint64_t stream, int64_t* traced);

/// applies the mirror layer to the hit pixels of primary.tile: out.radiance holds every
/// pixel's radiance without the layer, mirror[i] the weight r of tile pixel i (row-major over
/// the tile; 0 = no layer, also for pixels that see the sky). returns the rays it traced.
int64_t ShadeMirrorLayerTile(const FrameContext& ctx, const PrimaryHits& primary,
                             const float* mirror, float wetness, const FrameBuffers& out);

}  // namespace penumbra
