#pragma once
// the `realtime` tier: direct lighting with ray-traced shadows, one sample per pixel.
//
// per pixel, at the surface seen through the pixel centre:
//   L = Le + sum over lights  f(wo, wi) |n . wi| E_i V_i  + ambient
// with E_i the illuminance of one sample of light i (LightSampler; lights with an extent
// are jittered per pixel for soft shadows), V_i its visibility from one shadow ray, f the
// metallic-roughness BRDF (bsdf.h), and the sky ambient
//   ambient = Irradiance(n) V_sky / pi x (c_diff (1 - S) + S),   S = EnvBRDF(F0, n.v, roughness)
// (SkyModel::Irradiance: the unoccluded sky irradiance; S is Karis' analytic fit of the
// split-sum specular reflectance, "Physically based shading on mobile", Unreal Engine blog
// 2014), exact for a uniform unoccluded sky and a Lambertian surface (S = 0). rays that miss
// see SkyModel::Radiance.
//
// sky visibility V_sky: the sky is occluded like any light. every pixel traces one
// cosine-weighted shadow ray d around its shading normal; its direction comes from interleaved
// sampling (Keller and Heidrich, "Interleaved sampling", EGWR 2001): the 64 pixels of each
// 8 x 8 block take the centres of the 64 cells of an 8 x 8 grid over the hemisphere's unit
// square (cell order permuted and the grid toroidally shifted per frame from the frame key;
// no per-pixel jitter, so neighbouring pixels sample the same 64 directions and the filtered
// result is smooth, not noisy). a separable cross-bilateral filter over 15 x 15 pixels (tent
// kernel 8 - |offset| per axis, which weighs the 64 strata of every block equally; geometry
// weights (n_i . n_j)^4 times a tent in the distance of p_j from the tangent plane of p_i,
// relative to the pixel footprint) then estimates V_sky as the luminance-weighted visible
// fraction
//   V_sky(i) = sum_j w_ij Y(d_j) v_j / sum_j w_ij Y(d_j)
// with v_j the visibility of pixel j's ray and Y = SkyModel::LuminanceLookup (a ratio
// estimator: exactly 1 where nothing occludes, 0 where everything does, and weighted towards
// the bright parts of the sky). rays below the geometric surface count as occluded. the filter
// is a pass over the finished frame (EndFrame), so images do not depend on the thread count.
//
// shadow rays are skipped for lights that contribute less than kNegligibleLight of the
// pixel's unshadowed radiance (their contribution is added unshadowed). random numbers:
// Rng(ctx.PixelStream(u, v, 0)), two per light in light order; the frame's sky pattern from
// Rng(HashKeys(ctx.FrameKey(), kSkyPatternKey)).
//
// speed: a tile row of kLanes (16) pixels is shaded at once as SIMD lanes (BsdfLanes,
// LightSampler::SampleLanes) and its shadow rays towards one light form one Embree packet
// (RayScene::OccludedLanes); materials, textures and the sky are evaluated per pixel.

#include <vector>

#include "penumbra/render/integrator.h"

namespace penumbra {

/// lights below this fraction of a pixel's unshadowed radiance get no shadow ray.
constexpr float kNegligibleLight = 1e-3f;

/// direct lighting + occluded sky ambient, 1 sample per pixel. RenderTile is thread-safe for
/// distinct tiles between BeginFrame and EndFrame (it writes only its own pixels of the
/// per-frame sky buffers).
class RealtimeIntegrator final : public Integrator {
 public:
  /// per-pixel sky-visibility sample, written by RenderTile, filtered by EndFrame.
  struct SkyTap {
    float num = 0, den = 0;      ///< Y(d) v and Y(d) of the pixel's sky ray (0, 0: no sample)
    float tol = 0;               ///< plane-distance tolerance (m); 0 for pixels that see no surface
    Eigen::Vector3f n{0, 0, 1};  ///< unit shading normal
    Eigen::Vector3f p{0, 0, 0};  ///< hit point, world frame, m
    Eigen::Vector3f weight{0, 0, 0};  ///< Irradiance(n) / pi x reflectance: radiance at V = 1
  };

  void BeginFrame(const FrameContext& ctx) override;
  int64_t RenderTile(const FrameContext& ctx, const PrimaryHits& primary,
                     const FrameBuffers& out) const override;
  /// filters the sky visibility and adds the sky ambient to out.radiance.
  void EndFrame(const FrameContext& ctx, const FrameBuffers& out, ThreadPool* pool) override;

 private:
  int width_ = 0, height_ = 0;
  mutable std::vector<SkyTap> taps_;   // (H x W), row-major; RenderTile writes its pixels
  // the filter's fields, structure of arrays over a padded frame (realtime_integrator.cc).
  int padded_width_ = 0;
  size_t padded_size_ = 0;
  std::vector<float> planes_;
};

}  // namespace penumbra
