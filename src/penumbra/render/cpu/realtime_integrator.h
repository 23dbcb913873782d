#pragma once
// the `realtime` tier: direct lighting with ray-traced shadows, no random numbers.
//
// per pixel, at the surface seen through the pixel centre:
//   L = Le + sum over lights  f(wo, wi) |n . wi| E_i V_i  + ambient
// with E_i the illuminance of light i (LightSampler), V_i its visibility, f the
// metallic-roughness BRDF (bsdf.h), and the sky ambient
//   ambient = E_sky(p, n) / pi x (c_diff (1 - S) + S),   S = EnvBRDF(F0, n.v, roughness)
// where E_sky is the sky irradiance occluded by the static geometry (SkyIrradianceVolume, when
// the context has one; else the unoccluded SkyModel::Irradiance(n)) and S is Karis' analytic
// fit of the split-sum specular reflectance ("Physically based shading on mobile", Unreal
// Engine blog 2014); unoccluded, this is exact for a uniform sky and a Lambertian surface. rays
// that miss (from the camera or off a mirror) see SkyModel::Background: the MJCF skybox where
// there is one, else SkyModel::Radiance.
//
// point lights, spots without a radius and a sun without a disc: wi towards the light, V_i from
// one shadow ray. lights with an extent (a lamp's sphere, radius_m > 0; the sun's disc,
// angular radius > 0), render/light/lamp_math.h: E_i is the sphere's (or disc's) illuminance
// clipped by the surface's horizon in closed form (Snyder 1996, SphereLightCosine), f taken at the
// direction to its centre (tilted above the horizon where it straddles it), and V_i the
// fraction of visible shadow rays over the 5x5 pixels around the pixel on the same surface,
// each pixel's ray going through its own point of a 16-point Fibonacci lattice over the
// light's cone (a 4x4 ordered-dither assignment, LightStratum), and for pixels whose window sees
// both lit and shadowed verdicts (a penumbra) up to 4 points (64 in a window), as many as the
// light's share of the pixel's unshadowed luminance asks for (PenumbraLatticePoints: a faint
// lamp's penumbra needs few); a tile's outermost penumbra pixels, whose window the tile edge
// cuts, trace that many of the 64 points themselves (64, 32, 16 or 4), and a lamp's fraction is
// averaged once more over 3x3 pixels. the further points' rays go as 16-wide packets. why a
// lattice: one random point per pixel and frame gives salt-and-pepper speckle wherever a lamp is
// partly hidden or near the horizon, and different speckle every frame.
//
// shadow rays are skipped for lights that contribute less than kGpuNegligibleLight (1e-3) of
// the pixel's unshadowed radiance (ShadowRayWorthTracing, render/transport/realtime_shading.h;
// their contribution is added unshadowed). random numbers: only for the mirror layer's light
// samples, Rng(ctx.PixelStream(u, v, 0)) from draw number-of-lights on.
//
// written once with the CUDA backend (render/transport/realtime_*.h): the ambient term
// (AmbientRadiance), the lights' unshadowed contributions (ExtendedLightAxisOf,
// ExtendedLightContribution, PointLightContribution: templates over float and Lanes), the
// negligible-light rule, the shared visibility's windows, fractions and resolve, and the
// mirror layer (render/cpu/mirror_layer.h). this file is their driver: the tile loop, scratch
// buffers, Embree packets, the CPU's materials, sky lookups and view effects.
//
// adverse conditions (FrameContext::effects): surface wetness changes the material of
// upward-facing surfaces; each light's contribution is attenuated by the media between the
// surface and the light; the pixel's radiance L (surface or sky) becomes T L + L_media along the
// camera ray (render/media/media_realtime.h: closed-form fog, froxel volumes for grids and for fog
// light in-scatter, isotropic unoccluded sky in-scatter), and the nearest particle streak is
// alpha-composited over it (render/particles/particle_streaks.h). without effects nothing changes.
//
// speed: a tile row of kLanes (16) pixels is shaded at once as SIMD lanes (BsdfLanes,
// LightSampler::SampleLanes) and its first shadow rays towards one light form one Embree packet
// (RayScene::OccludedLanes); materials and textures are evaluated per pixel, textures filtered
// over the pixel's ray cone (render/material/material_eval.h, Camera::pixel_spread_rad), by the
// renderer before the tile is shaded (PrimaryHits::materials; a material's base, normal and
// metallic-roughness maps in one pass). the sky volume's probe weights are found once per 2x2
// pixel quad that sees one flat face, at the quad's mean hit point and the face's geometric
// normal (they vary over a probe spacing, tens of pixels), else per pixel; the resulting SH is
// evaluated at every pixel's own shading normal (SkyIrradianceVolume::Blend, IrradianceAt).

#include "penumbra/render/cpu/integrator.h"

namespace penumbra {

/// direct lighting + sky ambient, 1 sample per pixel. stateless, thread-safe.
class RealtimeIntegrator final : public Integrator {
 public:
  int64_t RenderTile(const FrameContext& ctx, const PrimaryHits& primary,
                     const FrameBuffers& out) const override;
  bool wants_primary_materials() const override { return true; }
};

}  // namespace penumbra
