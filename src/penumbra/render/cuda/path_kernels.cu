// the pathtraced tier's kernels (cuda_path.h): each thread runs the PB_HOST_DEVICE functions of
// render/transport/path_trace.h (a run of one pixel's samples, then a pixel's finish), which the
// CPU backend runs over Embree (render/cpu/path_tiles.h).

#include <cuda_runtime.h>

#include <algorithm>
#include <vector>

#include "penumbra/core/error.h"
#include "penumbra/render/cuda/cuda_device_buffer.h"
#include "penumbra/render/cuda/cuda_path.h"
#include "penumbra/render/cuda/media_grid_upload.h"
#include "penumbra/render/cuda/streak_upload.h"
#include "penumbra/render/transport/path_trace.h"

namespace penumbra::cuda {
namespace {

// the threads the path kernel aims at (an H100 holds 132 SMs x 2048): a frame of fewer pixels
// splits each pixel's samples into runs (PathRunsPerPixel).
constexpr int64_t kPathThreads = 1 << 18;

// run k of pixel (u, v) a thread (threadIdx.x over 64 pixels of a row, blockIdx.z the run):
// samples [k c, min((k + 1) c, spp)) with c = ceil(spp / runs), summed into partial[k n + i].
// kMedia: the frame has media (TracePath<true>); kParticles: it has particle streaks
// (TracePath<..., true>); frames with neither keep the kernel of before.
template <bool kMedia, bool kParticles>
__global__ void __launch_bounds__(64)
    PathRunKernel(PathFrameView pf, int runs, PathPartial* partial) {
  const int u = blockIdx.x * blockDim.x + threadIdx.x;
  const int v = blockIdx.y;
  if (u >= pf.rt.camera.width) return;
  const int k = blockIdx.z;
  const int c = (pf.spp + runs - 1) / runs;
  const int s0 = k * c, s1 = s0 + c < pf.spp ? s0 + c : pf.spp;
  const int64_t n = static_cast<int64_t>(pf.rt.camera.width) * pf.rt.camera.height;
  const int64_t i = static_cast<int64_t>(v) * pf.rt.camera.width + u;
  partial[k * n + i] =
      s0 < s1 ? PathSampleRange<kMedia, kParticles>(pf, BvhTracer{pf.rt.scene}, u, v, s0, s1)
              : PathPartial{};
}

// a pixel a thread: its runs' sums added in run order (no atomics), then its outputs.
__global__ void PathFinishKernel(PathFrameView pf, int runs, const PathPartial* partial) {
  const int u = blockIdx.x * blockDim.x + threadIdx.x;
  const int v = blockIdx.y * blockDim.y + threadIdx.y;
  if (u >= pf.rt.camera.width || v >= pf.rt.camera.height) return;
  const int64_t n = static_cast<int64_t>(pf.rt.camera.width) * pf.rt.camera.height;
  const int64_t i = static_cast<int64_t>(v) * pf.rt.camera.width + u;
  PathPartial p = partial[i];
  for (int k = 1; k < runs; ++k) {
    const PathPartial& q = partial[k * n + i];
    for (int c = 0; c < 3; ++c) p.L[c] += q.L[c], p.albedo[c] += q.albedo[c];
    p.albedo_count += q.albedo_count;
  }
  PathFinishPixel(pf, BvhTracer{pf.rt.scene}, u, v, p);
}

void LaunchPath(const PathFrameView& pf, PathPartial* partial, int runs, cudaStream_t stream) {
  const int W = pf.rt.camera.width, H = pf.rt.camera.height;
  const dim3 grid((W + 63) / 64, H, runs);
  const bool media = MediaAny(pf.media), particles = pf.streaks.num > 0;
  if (particles && media) {
    PathRunKernel<true, true><<<grid, 64, 0, stream>>>(pf, runs, partial);
  } else if (particles) {
    PathRunKernel<false, true><<<grid, 64, 0, stream>>>(pf, runs, partial);
  } else if (media) {
    PathRunKernel<true, false><<<grid, 64, 0, stream>>>(pf, runs, partial);
  } else {
    PathRunKernel<false, false><<<grid, 64, 0, stream>>>(pf, runs, partial);
  }
  Check(cudaGetLastError(), "PathRunKernel");
  PathFinishKernel<<<dim3((W + 7) / 8, (H + 7) / 8), dim3(8, 8), 0, stream>>>(pf, runs, partial);
  Check(cudaGetLastError(), "PathFinishKernel");
}

}  // namespace

struct DevicePath::Impl {
  Buffer marginal_pdf, marginal_cdf, marginal_guide, cond_pdf, cond_cdf, cond_guide;
  SkySamplingPod sky;
  Buffer radiance, albedo, normal, depth, partial;
  Buffer em_pods, em_le, em_pick, em_of_geom, em_cdf, em_vertices, em_faces, em_poses;
  PathEmitters emitters;
  Buffer media_pods, media_terms, grid_pods, grid_density, grid_emission;
  MediaSceneView media;
  StreakBuffers streak_buffers;
  PathStreaks streaks;
  PathFrameView last;  // the last Render's frame and sample runs (TimeKernel)
  int runs = 1;
  bool rendered = false;
};

DevicePath::DevicePath() : impl_(new Impl) {}
DevicePath::~DevicePath() { delete impl_; }

const SkySamplingPod& DevicePath::UploadSkySampling(const SkySamplingPod& h) {
  Impl& m = *impl_;
  const size_t rows = static_cast<size_t>(h.rows), cols = static_cast<size_t>(h.cols);
  m.marginal_pdf.Upload(h.marginal.pdf, sizeof(float) * rows, nullptr);
  m.marginal_cdf.Upload(h.marginal.cdf, sizeof(float) * (rows + 1), nullptr);
  m.marginal_guide.Upload(h.marginal.guide, sizeof(int32_t) * rows, nullptr);
  m.cond_pdf.Upload(h.cond_pdf, sizeof(float) * rows * cols, nullptr);
  m.cond_cdf.Upload(h.cond_cdf, sizeof(float) * rows * (cols + 1), nullptr);
  m.cond_guide.Upload(h.cond_guide, sizeof(int32_t) * rows * cols, nullptr);
  Check(cudaStreamSynchronize(nullptr), "uploading the sky's sampling tables");
  m.sky = h;
  m.sky.marginal.pdf = m.marginal_pdf.as<float>();
  m.sky.marginal.cdf = m.marginal_cdf.as<float>();
  m.sky.marginal.guide = m.marginal_guide.as<int32_t>();
  m.sky.cond_pdf = m.cond_pdf.as<float>();
  m.sky.cond_cdf = m.cond_cdf.as<float>();
  m.sky.cond_guide = m.cond_guide.as<int32_t>();
  return m.sky;
}

const PathEmitters& DevicePath::UploadEmitters(const PathEmitters& h) {
  Impl& m = *impl_;
  // the part cdfs and meshes of every emitter in one array each, the pods pointing into them
  std::vector<EmitterPod> pods(h.pods, h.pods + h.num);
  std::vector<double> cdf;
  std::vector<float> vertices;
  std::vector<int32_t> faces;
  std::vector<int64_t> cdf_at(h.num, -1), vertex_at(h.num, -1), face_at(h.num, -1);
  for (int k = 0; k < h.num; ++k) {
    const EmitterPod& e = h.pods[k];
    if (e.num_parts > 0 && e.part_cdf != nullptr) {
      cdf_at[k] = static_cast<int64_t>(cdf.size());
      cdf.insert(cdf.end(), e.part_cdf, e.part_cdf + e.num_parts + 1);
    }
    if (e.faces != nullptr && e.vertices != nullptr && e.num_parts > 0) {
      int32_t max_vertex = 0;
      for (int i = 0; i < 3 * e.num_parts; ++i) max_vertex = std::max(max_vertex, e.faces[i]);
      face_at[k] = static_cast<int64_t>(faces.size());
      faces.insert(faces.end(), e.faces, e.faces + 3 * e.num_parts);
      vertex_at[k] = static_cast<int64_t>(vertices.size());
      vertices.insert(vertices.end(), e.vertices, e.vertices + 3 * (max_vertex + 1));
    }
  }
  m.em_cdf.Upload(cdf.data(), sizeof(double) * cdf.size(), nullptr);
  m.em_vertices.Upload(vertices.data(), sizeof(float) * vertices.size(), nullptr);
  m.em_faces.Upload(faces.data(), sizeof(int32_t) * faces.size(), nullptr);
  for (int k = 0; k < h.num; ++k) {
    pods[k].part_cdf = cdf_at[k] >= 0 ? m.em_cdf.as<double>() + cdf_at[k] : nullptr;
    pods[k].vertices = vertex_at[k] >= 0 ? m.em_vertices.as<float>() + vertex_at[k] : nullptr;
    pods[k].faces = face_at[k] >= 0 ? m.em_faces.as<int32_t>() + face_at[k] : nullptr;
  }
  m.em_pods.Upload(pods.data(), sizeof(EmitterPod) * pods.size(), nullptr);
  m.em_le.Upload(h.Le, sizeof(Float3) * h.num, nullptr);
  m.em_pick.Upload(h.pick_cdf, sizeof(double) * (h.num + 1), nullptr);
  m.em_of_geom.Upload(h.emitter_of_geom, sizeof(int32_t) * h.num_geoms, nullptr);
  Check(cudaStreamSynchronize(nullptr), "uploading the emitters");
  m.emitters = h;
  m.emitters.pods = m.em_pods.as<EmitterPod>();
  m.emitters.Le = m.em_le.as<Float3>();
  m.emitters.pick_cdf = m.em_pick.as<double>();
  m.emitters.emitter_of_geom = m.em_of_geom.as<int32_t>();
  m.emitters.poses = nullptr;
  return m.emitters;
}

const PathEmitters& DevicePath::UploadEmitterPoses(const double* poses) {
  Impl& m = *impl_;
  m.em_poses.Upload(poses, sizeof(double) * 12 * m.emitters.num, nullptr);
  Check(cudaStreamSynchronize(nullptr), "uploading the emitter poses");
  m.emitters.poses = m.em_poses.as<double>();
  return m.emitters;
}

const MediaSceneView& DevicePath::UploadMedia(const MediaSceneView& h) {
  Impl& m = *impl_;
  // every grid's density (and emission) in one array each, the grid pods pointing into them
  const MediaGridPod* grids = UploadMediaGrids(h.grids, h.num_grids, &m.grid_density,
                                               &m.grid_emission, &m.grid_pods, nullptr);
  m.media_pods.Upload(h.media, sizeof(MediumPod) * h.num_media, nullptr);
  m.media_terms.Upload(h.terms, sizeof(MediumTracePod) * h.num_media, nullptr);
  Check(cudaStreamSynchronize(nullptr), "uploading the media");
  m.media = h;
  m.media.media = h.num_media > 0 ? m.media_pods.as<MediumPod>() : nullptr;
  m.media.terms = h.num_media > 0 ? m.media_terms.as<MediumTracePod>() : nullptr;
  m.media.grids = grids;
  return m.media;
}

const PathStreaks& DevicePath::UploadStreaks(const PathStreaks& h) {
  Impl& m = *impl_;
  m.streaks = m.streak_buffers.Upload(h, nullptr);
  if (h.num > 0) Check(cudaStreamSynchronize(nullptr), "uploading the particle streaks");
  return m.streaks;
}

void DevicePath::Render(DeviceScene* scene, const PathFrameView& frame, PathBuffers* out) {
  Impl& m = *impl_;
  cudaStream_t stream = static_cast<cudaStream_t>(scene->stream());
  const int W = frame.rt.camera.width, H = frame.rt.camera.height;
  const int64_t n = static_cast<int64_t>(W) * H;
  m.radiance.Reserve(sizeof(Float3) * n);
  m.albedo.Reserve(sizeof(Float3) * n);
  m.normal.Reserve(sizeof(Float3) * n);
  m.depth.Reserve(sizeof(float) * n);
  PathFrameView pf = frame;
  pf.radiance = m.radiance.as<Float3>();
  pf.albedo = m.albedo.as<Float3>();
  pf.normal = m.normal.as<Float3>();
  pf.depth = m.depth.as<float>();
  const int runs = PathRunsPerPixel(n, pf.spp, kPathThreads);
  m.partial.Reserve(sizeof(PathPartial) * n * runs);
  LaunchPath(pf, m.partial.as<PathPartial>(), runs, stream);
  out->Resize(n);
  m.radiance.Download(out->radiance.data(), sizeof(Float3) * n, stream);
  m.albedo.Download(out->albedo.data(), sizeof(Float3) * n, stream);
  m.normal.Download(out->normal.data(), sizeof(Float3) * n, stream);
  m.depth.Download(out->depth.data(), sizeof(float) * n, stream);
  Check(cudaStreamSynchronize(stream), "the path kernels' outputs");
  m.last = pf;
  m.runs = runs;
  m.rendered = true;
}

double DevicePath::TimeKernel(DeviceScene* scene, int count) {
  Impl& m = *impl_;
  if (!m.rendered) throw Error("DevicePath::TimeKernel: no frame rendered yet");
  cudaStream_t stream = static_cast<cudaStream_t>(scene->stream());
  return TimeOnStream(stream, count,
                      [&] { LaunchPath(m.last, m.partial.as<PathPartial>(), m.runs, stream); });
}

}  // namespace penumbra::cuda
