#pragma once
// the `pathtraced` tier: unidirectional path tracing with next-event estimation and multiple
// importance sampling (Veach, "Robust Monte Carlo methods for light transport simulation",
// PhD thesis, Stanford 1997, ch. 9; power heuristic with beta = 2).
//
// per pixel, settings.samples_per_pixel paths, each from a camera ray jittered uniformly over
// the pixel (box filter). at every surface vertex, up to settings.max_bounces of them:
//   - emission Le of the surface (Material::emission, two-sided) is added: with weight 1 when
//     seen by the camera ray, else MIS-weighted against the emitter sampling of the previous
//     vertex (EmitterSampler::Pdf; weight 1 for shapes it does not sample);
//   - next-event estimation, one sample per light, each with a shadow ray:
//       point / spot / directional lights without extent, and lights that cast no shadow:
//         delta lights, weight 1 (LightSampler);
//       directional lights with an angular radius (sun disc, radiance E / Omega_cone) and
//       point / spot lamps with a radius (spheres of radiance I s / (pi r^2), s the spot
//       factor towards the shading point): uniform cone sampling (LightSampler), MIS-weighted;
//       the sky (SkyModel::Sample), MIS-weighted; one emissive geom picked by power
//       (EmitterSampler), MIS-weighted;
//   - the BSDF (bsdf.h) samples the next direction; rays that leave the scene add the sky and
//     any sun disc they point into, rays that meet a lamp sphere add its radiance and end,
//     both MIS-weighted against the light sampling at the vertex they left (camera rays: 1).
// lamp spheres and sun discs are thus visible to every ray in this tier (they are not in the
// realtime tier); lamps also block shadow rays towards other lights. with max_bounces = b a
// path gathers light that scattered at most b times (b = 1: direct lighting).
// Russian roulette from the 4th vertex on (after 3 bounces): a path continues with probability
// q = min(1, max channel of its throughput) and is reweighted by 1 / q (unbiased).
//
// adverse conditions (FrameContext::effects, render/cpu/media_frame.h), when present:
//   - participating media (render/media/media_scene.h): every ray segment is tracked from its
//   origin
//     to the surface, lamp or infinity by spectral delta tracking; a real scattering event is
//     a path vertex (counted against max_bounces, Russian roulette as at surfaces) with the
//     same next-event estimation as a surface but the media's Henyey-Greenstein phase mixture
//     in place of the BSDF (MIS weights use the phase density), and continues along a phase
//     sample; absorption ends the path; grid emission is gathered at every tentative
//     collision. every shadow ray (surface and medium vertices) is weighted by the media's
//     transmittance (exact for homogeneous media, ratio tracking in grids), so the sky behind
//     an unbounded fog is never reached.
//   - particles (render/embree/particle_scene.h): a camera ray that meets a streak stops there with
//     probability alpha (coverage), drawing the streak's radiance attenuated by the media in
//     front of it; secondary rays do not see particles.
//   - surface wetness (ApplySurfaceWetness) changes the material of upward-facing surfaces.
// without effects the tier draws no extra random numbers: its images do not depend on the
// effects code.
//
// textures are filtered over the pixel's ray cone (render/material/material_eval.h): its spread
// angle is Camera::pixel_spread_rad and its width at a vertex is that angle times the length of the
// path from the camera to the vertex (the cone of a chain of flat mirrors; the paper's spread from
// surface curvature and roughness is left out, so after rough bounces the footprint is
// underestimated and textures are sampled sharper than the cone of the path would need).
//
// outputs per pixel: the mean radiance; the denoiser guides (FrameBuffers): albedo = mean base
// colour of the first surface over the samples that hit one, normal = shading normal of the
// pixel-centre hit (consistent with the renderer's depth image). non-finite path values are
// dropped (counted as zero).
//
// random numbers: every path draws from Rng(ctx.PixelStream(u, v, s)) only, so images are
// bit-identical for any thread count and tile order.
//
// stopping: before every sample (one path of one pixel) the tier reads FrameContext::
// stop_request; once it is set the tile is left unfinished and FrameContext::stopped is set, so
// a stop (SIGINT) waits for at most one path per render thread, not for the frame's
// samples_per_pixel passes. a render that is not stopped is the same as without the check.

#include "penumbra/render/cpu/integrator.h"
#include "penumbra/render/light/emitter_sampler.h"

namespace penumbra {

/// Russian roulette starts at this path vertex index (0 = first hit), i.e. after 3 bounces.
constexpr int kRussianRouletteStartVertex = 3;

/// unidirectional path tracer with NEE and MIS. immutable after construction, thread-safe.
class PathIntegrator final : public Integrator {
 public:
  /// collects the emissive geoms of `scene` (which must outlive this object).
  /// @throws Error if an emissive mesh geom refers to a missing mesh.
  explicit PathIntegrator(const SceneDescription& scene);

  int64_t RenderTile(const FrameContext& ctx, const PrimaryHits& primary,
                     const FrameBuffers& out) const override;

  const EmitterSampler& emitters() const { return emitters_; }

 private:
  EmitterSampler emitters_;
};

}  // namespace penumbra
