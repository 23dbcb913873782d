// the realtime tier's primary geometry, sky-term and mirror-layer kernels (realtime_kernels.cuh).

#include "penumbra/render/cuda/realtime_kernels.cuh"

namespace penumbra::cuda::realtime {
namespace {

// the primary geometry, depth and material terms, at most 102 registers (5 blocks of 128
// threads an SM).
template <class Frames>
__global__ void __launch_bounds__(128, 5)
    GeometryKernel(Frames frames, PixelGeometry* geometry, float* depth, SurfaceTerms* surfaces) {
  const RealtimeFrameView& f = frames.get();
  const FramePixel p = PixelOf(f);
  if (!p) return;
  float t;
  geometry[p.k] = PrimaryGeometry(f, p.u, p.v, &t, nullptr, &surfaces[p.k]);
  depth[p.k] = t;
}

// the sky terms (realtime_shading.h): one thread per 2x2 quad of primary geometry (the quads
// that share one probe blend), and one per mirrored ray.
template <class Frames>
__global__ void SkyQuadKernel(Frames frames, Float3* sky) {
  const RealtimeFrameView& f = frames.get();
  const int qu = blockIdx.x * blockDim.x + threadIdx.x;
  const int qv = blockIdx.y * blockDim.y + threadIdx.y;
  const int W = f.camera.width, H = f.camera.height;
  if (2 * qu >= W || 2 * qv >= H) return;
  QuadSkyTerms(f.sky, f.volume, f.geometry, W, H, 2 * qu, 2 * qv, sky + CameraOffset(f));
}

template <class Frames>
__global__ void MirrorSkyKernel(Frames frames, Float3* mirror_sky) {
  const RealtimeFrameView& f = frames.get();
  const FramePixel p = PixelOf(f);
  if (p && f.any_mirror != 0)
    MirrorSkyTerm(f.sky, f.volume, f.mirror_geometry[p.i], &mirror_sky[p.k]);
}

// the mirror layer (realtime_shading.h): the mirrored rays after the geometry kernel; their
// shading and the blend after the shared visibility. they run only where the frame has a mirror
// layer (a batch launches them for every camera when one of its worlds has one).
template <class Frames>
__global__ void MirrorTraceKernel(Frames frames) {
  const RealtimeFrameView& f = frames.get();
  const FramePixel p = PixelOf(f);
  if (p && f.any_mirror != 0) TraceMirrorRay(f, p.u, p.v);
}

template <class Frames>
__global__ void MirrorShadeKernel(Frames frames) {
  const RealtimeFrameView& f = frames.get();
  const FramePixel p = PixelOf(f);
  if (p && f.any_mirror != 0) ShadeMirrorHit(f, p.u, p.v);
}

template <class Frames>
__global__ void MirrorBlendKernel(Frames frames, Float3* radiance) {
  const RealtimeFrameView& f = frames.get();
  const FramePixel p = PixelOf(f);
  if (p && f.any_mirror != 0) radiance[p.k] = ApplyMirrorLayer(f, p.u, p.v, radiance[p.k]);
}

}  // namespace

template <class Frames>
void LaunchGeometry(Frames frames, dim3 grid, PixelGeometry* geometry, float* depth,
                    SurfaceTerms* surfaces, cudaStream_t stream) {
  LaunchKernel("GeometryKernel", GeometryKernel<Frames>, grid, PixelBlock(), 0, stream, frames,
               geometry, depth, surfaces);
}

template <class Frames>
void LaunchSkyQuads(Frames frames, dim3 quads, Float3* sky, cudaStream_t stream) {
  LaunchKernel("SkyQuadKernel", SkyQuadKernel<Frames>, quads, PixelBlock(), 0, stream, frames, sky);
}

template <class Frames>
void LaunchMirrorTrace(Frames frames, dim3 grid, cudaStream_t stream) {
  LaunchKernel("MirrorTraceKernel", MirrorTraceKernel<Frames>, grid, PixelBlock(), 0, stream,
               frames);
}

template <class Frames>
void LaunchMirrorSky(Frames frames, dim3 grid, Float3* mirror_sky, cudaStream_t stream) {
  LaunchKernel("MirrorSkyKernel", MirrorSkyKernel<Frames>, grid, PixelBlock(), 0, stream, frames,
               mirror_sky);
}

template <class Frames>
void LaunchMirrorShade(Frames frames, dim3 grid, cudaStream_t stream) {
  LaunchKernel("MirrorShadeKernel", MirrorShadeKernel<Frames>, grid, PixelBlock(), 0, stream,
               frames);
}

template <class Frames>
void LaunchMirrorBlend(Frames frames, dim3 grid, Float3* radiance, cudaStream_t stream) {
  LaunchKernel("MirrorBlendKernel", MirrorBlendKernel<Frames>, grid, PixelBlock(), 0, stream,
               frames, radiance);
}

#define PB_REALTIME_GEOMETRY(Frames)                                                        \
  template void LaunchGeometry<Frames>(Frames, dim3, PixelGeometry*, float*, SurfaceTerms*, \
                                       cudaStream_t);                                       \
  template void LaunchSkyQuads<Frames>(Frames, dim3, Float3*, cudaStream_t);                \
  template void LaunchMirrorTrace<Frames>(Frames, dim3, cudaStream_t);                      \
  template void LaunchMirrorSky<Frames>(Frames, dim3, Float3*, cudaStream_t);               \
  template void LaunchMirrorShade<Frames>(Frames, dim3, cudaStream_t);                      \
  template void LaunchMirrorBlend<Frames>(Frames, dim3, Float3*, cudaStream_t);
PB_REALTIME_GEOMETRY(OneFrame)
PB_REALTIME_GEOMETRY(BatchFrames)
#undef PB_REALTIME_GEOMETRY

}  // namespace penumbra::cuda::realtime
