// the drops culled on the device (cuda_streak_cull.h). compiled with -fmad=false
// (CMakeLists.txt): no multiply-add is contracted where the host rounds twice.

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <cub/device/device_reduce.cuh>
#include <cub/device/device_scan.cuh>
#include <string>
#include <utility>

#include "penumbra/core/error.h"
#include "penumbra/render/cuda/cuda_device_buffer.h"
#include "penumbra/render/cuda/cuda_streak_cull.h"
#include "penumbra/render/particles/streak_cull_math.h"

namespace penumbra::cuda {

namespace {

// what the decision kernel reads of a frame's drops: per set its first drop's global index
// (num_sets + 1 of them) and flags, the sets' arrays concatenated.
struct DropArrays {
  const float* p = nullptr;  // 3 per drop, world m
  const float* v = nullptr;  // 3 per drop, m/s
  const float* r = nullptr;  // per drop, m
  const int64_t* first = nullptr;
  const StreakCullSet* sets = nullptr;
  int32_t num_sets = 0;
  int32_t n = 0;
};

// per drop: its decision (StreakCullDrop) into kept (1: a streak), culled (1: rain culled as
// invisible), bad (its index if non-finite, else n) and, if kept, its streak's fields.
__global__ void DecideDropsKernel(DropArrays d, StreakCullFrame f, int32_t* kept, int32_t* culled,
                                  int32_t* bad, StreakCullOut* out, int32_t* set_of) {
  const int32_t g = static_cast<int32_t>(blockIdx.x * blockDim.x + threadIdx.x);
  if (g >= d.n) return;
  int32_t s = 0;
  while (g >= d.first[s + 1]) ++s;
  const Float3 p{d.p[3 * g], d.p[3 * g + 1], d.p[3 * g + 2]};
  const Float3 v{d.v[3 * g], d.v[3 * g + 1], d.v[3 * g + 2]};
  const float r = d.r[g];
  kept[g] = 0;
  culled[g] = 0;
  bad[g] = d.n;
  set_of[g] = s;
  if (!(isfinite(p.x) && isfinite(p.y) && isfinite(p.z) && isfinite(v.x) && isfinite(v.y) &&
        isfinite(v.z) && isfinite(r))) {
    bad[g] = g;
    return;
  }
  const int32_t verdict = StreakCullDrop(f, d.sets[s], p, v, r, &out[g]);
  kept[g] = verdict == kStreakDrawn ? 1 : 0;
  culled[g] = verdict == kStreakCulled ? 1 : 0;
}

// the kept drops' streaks at their place in (set, index) order (at: the exclusive sum of kept).
__global__ void WriteStreaksKernel(DropArrays d, const int32_t* kept, const int32_t* at,
                                   const StreakCullOut* out, const int32_t* set_of,
                                   StreakPod* pods) {
  const int32_t g = static_cast<int32_t>(blockIdx.x * blockDim.x + threadIdx.x);
  if (g >= d.n || kept[g] == 0) return;
  const StreakCullOut& o = out[g];
  StreakPod pod;
  pod.a[0] = d.p[3 * g];
  pod.a[1] = d.p[3 * g + 1];
  pod.a[2] = d.p[3 * g + 2];
  pod.b[0] = o.q.x;
  pod.b[1] = o.q.y;
  pod.b[2] = o.q.z;
  pod.r = o.r_wide;
  pod.alpha = o.alpha;
  pod.prim = at[g];
  pod.set = set_of[g];
  pods[at[g]] = pod;
}

// the totals: streaks = at[n - 1] + kept[n - 1].
__global__ void CountKernel(const int32_t* kept, const int32_t* at, int32_t n, int32_t* totals) {
  totals[0] = at[n - 1] + kept[n - 1];
}

}  // namespace

struct DeviceStreakCull::Impl {
  cudaStream_t stream = nullptr;
  Buffer inputs, roof;
  PinnedBuffer staged;  // the drops and the small inputs, copied in one transfer
  // the roof on the device: of which map (pointer, size, version; ShelterPod)
  const float* roof_of = nullptr;
  int64_t roof_cells = 0;
  uint64_t roof_version = 0;
  Buffer kept, culled, bad, at, out, set_of, pods, totals, temp;
  // the counts' copy back (streaks, culled rain, first non-finite drop) and the event after
  // the last Queue's work; pending: not yet Finished
  PinnedBuffer totals_host;
  cudaEvent_t done = nullptr;
  // timing events of the last Queue: before the inputs' transfer, after it, after the counts
  cudaEvent_t began = nullptr, uploaded = nullptr, counted = nullptr;
  bool pending = false;
  int32_t n = 0;  // the last Queue's drops
  std::vector<int64_t> first_host;
  std::vector<std::pair<int32_t, int64_t>> chunks;  // (set, first drop) of each staging chunk
  std::vector<uint8_t> chunk_kept;  // per chunk: its velocities and radii were staged already
  // the layout (sets' first drops, media, bytes) of the inputs on the device, and whether they
  // hold a whole Queue's inputs (a grown buffer holds none)
  std::vector<int64_t> device_first;
  int32_t device_media = -1;
  size_t device_total = 0;
  bool device_whole = false;
  // the highest priority: the culling's blocks go before the waiting blocks of the frame's
  // shading kernels it overlaps (CudaRenderer's late streaks)
  Impl() {
    int least = 0, greatest = 0;
    Check(cudaDeviceGetStreamPriorityRange(&least, &greatest), "cudaDeviceGetStreamPriorityRange");
    Check(cudaStreamCreateWithPriority(&stream, cudaStreamNonBlocking, greatest),
          "cudaStreamCreateWithPriority");
    Check(cudaEventCreateWithFlags(&done, cudaEventDisableTiming), "cudaEventCreate");
    for (cudaEvent_t* e : {&began, &uploaded, &counted})
      Check(cudaEventCreate(e), "cudaEventCreate");
    totals_host.Reserve(sizeof(int32_t) * 4);
  }
  ~Impl() {
    for (cudaEvent_t e : {began, uploaded, counted})
      if (e != nullptr) cudaEventDestroy(e);
    if (done != nullptr) cudaEventDestroy(done);
    if (stream != nullptr) cudaStreamDestroy(stream);
  }
};

DeviceStreakCull::DeviceStreakCull() : impl_(std::make_unique<Impl>()) {}
DeviceStreakCull::~DeviceStreakCull() = default;

const StreakPod* DeviceStreakCull::device_streaks() const {
  return bound_ > 0 ? impl_->pods.as<StreakPod>() : nullptr;
}

const int32_t* DeviceStreakCull::device_count() const {
  return bound_ > 0 ? impl_->totals.as<int32_t>() : nullptr;
}

void DeviceStreakCull::Download(std::vector<StreakPod>* out) {
  Finish();
  out->resize(count_);
  if (count_ == 0) return;
  impl_->pods.Download(out->data(), sizeof(StreakPod) * count_, impl_->stream);
  Check(cudaStreamSynchronize(impl_->stream), "cudaStreamSynchronize");
}

void DeviceStreakCull::Run(const DropSet* sets, int32_t num_sets, const StreakCullFrame& frame,
                           const StreakCullSet* flags, const ParallelFn& parallel) {
  const auto t0 = std::chrono::steady_clock::now();
  Queue(sets, num_sets, frame, flags, parallel);
  Finish();
  run_ms_ =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

void DeviceStreakCull::Finish() {
  Impl& m = *impl_;
  if (!m.pending) return;
  m.pending = false;
  Check(cudaEventSynchronize(m.done), "cudaEventSynchronize");
  float upload = 0, cull = 0;
  Check(cudaEventElapsedTime(&upload, m.began, m.uploaded), "cudaEventElapsedTime");
  Check(cudaEventElapsedTime(&cull, m.uploaded, m.counted), "cudaEventElapsedTime");
  device_upload_ms_ = upload;
  device_cull_ms_ = cull;
  const int32_t* totals = m.totals_host.as<int32_t>();
  if (totals[2] < m.n) {
    const int64_t g = totals[2];
    int32_t s = 0;
    while (g >= m.first_host[s + 1]) ++s;
    throw NonFiniteParticleError(static_cast<size_t>(s), static_cast<size_t>(g - m.first_host[s]));
  }
  count_ = totals[0];
  culled_ = totals[1];
}

void DeviceStreakCull::Queue(const DropSet* sets, int32_t num_sets, const StreakCullFrame& frame,
                             const StreakCullSet* flags, const ParallelFn& parallel,
                             void* wait_stream) {
  const auto t0 = std::chrono::steady_clock::now();
  Impl& m = *impl_;
  const cudaStream_t st = m.stream;
  // an earlier Queue's work done (its staging and counts are reused), without its counts
  if (m.pending) {
    m.pending = false;
    Check(cudaEventSynchronize(m.done), "cudaEventSynchronize");
  }
  count_ = 0;
  culled_ = 0;
  bound_ = 0;
  m.n = 0;
  m.first_host.assign(static_cast<size_t>(num_sets) + 1, 0);
  for (int32_t s = 0; s < num_sets; ++s) m.first_host[s + 1] = m.first_host[s] + sets[s].n;
  const int64_t n64 = m.first_host.back();
  if (n64 == 0) {
    run_ms_ = stage_ms_ = 0;
    return;
  }
  if (n64 >= INT32_MAX) throw Error("DeviceStreakCull: more than 2^31 - 1 drops");
  const int32_t n = static_cast<int32_t>(n64);
  m.n = n;
  // every input in one page-locked block, laid out as on the device (each part 16-byte aligned):
  // the drops' positions, velocities and radii set after set (copied over `parallel`), then
  // the sets' first drops and flags and the media; one asynchronous transfer
  const auto align = [](size_t b) { return (b + 15) / 16 * 16; };
  const size_t nn = static_cast<size_t>(n);
  size_t at_part[6], total = 0;
  const size_t part_bytes[6] = {sizeof(float) * 3 * nn,
                                sizeof(float) * 3 * nn,
                                sizeof(float) * nn,
                                sizeof(int64_t) * (static_cast<size_t>(num_sets) + 1),
                                sizeof(StreakCullSet) * static_cast<size_t>(num_sets),
                                sizeof(StreakCullMedium) * static_cast<size_t>(frame.num_media)};
  for (int k = 0; k < 6; ++k) {
    at_part[k] = total;
    total += align(part_bytes[k]);
  }
  m.staged.Reserve(total);
  char* host = m.staged.as<char>();
  float* hp = reinterpret_cast<float*>(host + at_part[0]);
  float* hv = reinterpret_cast<float*>(host + at_part[1]);
  float* hr = reinterpret_cast<float*>(host + at_part[2]);
  // chunks of drops, each within one set
  constexpr int64_t kChunk = 16384;
  m.chunks.clear();
  for (int32_t s = 0; s < num_sets; ++s)
    for (int64_t i = 0; i < sets[s].n; i += kChunk) m.chunks.push_back({s, i});
  // the velocities and radii are copied only where they differ from the staged ones (a rain
  // drop keeps both from frame to frame; the staging always ends up holding this Queue's)
  const int64_t num_chunks = static_cast<int64_t>(m.chunks.size());
  m.chunk_kept.assign(static_cast<size_t>(num_chunks), 0);
  const auto copy_chunk = [&](int64_t c) {
    const int32_t s = m.chunks[c].first;
    const int64_t i0 = m.chunks[c].second, k = std::min(kChunk, sets[s].n - i0);
    const int64_t g = m.first_host[s] + i0;
    std::memcpy(hp + 3 * g, sets[s].p + 3 * i0, sizeof(float) * 3 * k);
    const size_t v_bytes = sizeof(float) * 3 * k, r_bytes = sizeof(float) * k;
    const bool v_kept = std::memcmp(hv + 3 * g, sets[s].v + 3 * i0, v_bytes) == 0;
    if (!v_kept) std::memcpy(hv + 3 * g, sets[s].v + 3 * i0, v_bytes);
    const bool r_kept = std::memcmp(hr + g, sets[s].r + i0, r_bytes) == 0;
    if (!r_kept) std::memcpy(hr + g, sets[s].r + i0, r_bytes);
    m.chunk_kept[c] = v_kept && r_kept ? 1 : 0;
  };
  if (parallel)
    parallel(num_chunks, copy_chunk);
  else
    for (int64_t c = 0; c < num_chunks; ++c) copy_chunk(c);
  std::memcpy(host + at_part[3], m.first_host.data(), part_bytes[3]);
  if (num_sets > 0) std::memcpy(host + at_part[4], flags, part_bytes[4]);
  if (frame.num_media > 0) std::memcpy(host + at_part[5], frame.media, part_bytes[5]);
  // the transfer: without the velocities and radii when the device holds them already (the
  // last Queue's whole inputs in this layout, and every chunk's staged as they were)
  const size_t grown_from = m.inputs.bytes;
  m.inputs.Reserve(total);
  const bool kept =
      m.device_whole && m.inputs.bytes == grown_from && total == m.device_total &&
      frame.num_media == m.device_media && m.first_host == m.device_first &&
      std::all_of(m.chunk_kept.begin(), m.chunk_kept.end(), [](uint8_t k) { return k != 0; });
  m.device_whole = false;  // until the transfer is queued
  Check(cudaEventRecord(m.began, st), "cudaEventRecord");
  if (kept) {
    Check(cudaMemcpyAsync(m.inputs.p, host, part_bytes[0], cudaMemcpyHostToDevice, st),
          "cudaMemcpyAsync");
    Check(cudaMemcpyAsync(m.inputs.as<char>() + at_part[3], host + at_part[3], total - at_part[3],
                          cudaMemcpyHostToDevice, st),
          "cudaMemcpyAsync");
    upload_bytes_ = part_bytes[0] + (total - at_part[3]);
  } else {
    m.inputs.Upload(host, total, st);
    upload_bytes_ = total;
  }
  m.device_whole = true;
  m.device_total = total;
  m.device_media = frame.num_media;
  m.device_first = m.first_host;
  Check(cudaEventRecord(m.uploaded, st), "cudaEventRecord");
  char* dev = m.inputs.as<char>();
  StreakCullFrame f = frame;
  if (f.num_media > 0) f.media = reinterpret_cast<const StreakCullMedium*>(dev + at_part[5]);
  // the shelter's roof: uploaded again only when the map changed (ShelterPod::version)
  if (f.shelter.roof != nullptr) {
    const int64_t cells = static_cast<int64_t>(f.shelter.nx) * f.shelter.ny;
    if (m.roof_of != f.shelter.roof || m.roof_cells != cells ||
        m.roof_version != f.shelter.version) {
      m.roof.Upload(f.shelter.roof, sizeof(float) * static_cast<size_t>(cells), st);
      m.roof_of = f.shelter.roof;
      m.roof_cells = cells;
      m.roof_version = f.shelter.version;
    }
    f.shelter.roof = m.roof.as<float>();
  }
  stage_ms_ =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  DropArrays d;
  d.p = reinterpret_cast<const float*>(dev + at_part[0]);
  d.v = reinterpret_cast<const float*>(dev + at_part[1]);
  d.r = reinterpret_cast<const float*>(dev + at_part[2]);
  d.first = reinterpret_cast<const int64_t*>(dev + at_part[3]);
  d.sets = reinterpret_cast<const StreakCullSet*>(dev + at_part[4]);
  d.num_sets = num_sets;
  d.n = n;
  m.kept.Reserve(sizeof(int32_t) * n);
  m.culled.Reserve(sizeof(int32_t) * n);
  m.bad.Reserve(sizeof(int32_t) * n);
  m.at.Reserve(sizeof(int32_t) * n);
  m.set_of.Reserve(sizeof(int32_t) * n);
  m.out.Reserve(sizeof(StreakCullOut) * n);
  m.pods.Reserve(sizeof(StreakPod) * n);
  m.totals.Reserve(sizeof(int32_t) * 4);
  constexpr int kBlock = 256;
  const int blocks = (n + kBlock - 1) / kBlock;
  LaunchKernel("DecideDropsKernel", DecideDropsKernel, blocks, kBlock, 0, st, d, f,
               m.kept.as<int32_t>(), m.culled.as<int32_t>(), m.bad.as<int32_t>(),
               m.out.as<StreakCullOut>(), m.set_of.as<int32_t>());
  // the scan and the two reductions (their temporary storage: the largest of the three)
  int32_t* totals = m.totals.as<int32_t>();
  size_t scan_bytes = 0, sum_bytes = 0, min_bytes = 0;
  Check(cub::DeviceScan::ExclusiveSum(nullptr, scan_bytes, m.kept.as<int32_t>(), m.at.as<int32_t>(),
                                      n, st),
        "cub::DeviceScan");
  Check(cub::DeviceReduce::Sum(nullptr, sum_bytes, m.culled.as<int32_t>(), totals + 1, n, st),
        "cub::DeviceReduce::Sum");
  Check(cub::DeviceReduce::Min(nullptr, min_bytes, m.bad.as<int32_t>(), totals + 2, n, st),
        "cub::DeviceReduce::Min");
  size_t temp_bytes = std::max(scan_bytes, std::max(sum_bytes, min_bytes));
  m.temp.Reserve(temp_bytes > 0 ? temp_bytes : 1);
  Check(cub::DeviceScan::ExclusiveSum(m.temp.p, scan_bytes, m.kept.as<int32_t>(),
                                      m.at.as<int32_t>(), n, st),
        "cub::DeviceScan");
  Check(cub::DeviceReduce::Sum(m.temp.p, sum_bytes, m.culled.as<int32_t>(), totals + 1, n, st),
        "cub::DeviceReduce::Sum");
  Check(cub::DeviceReduce::Min(m.temp.p, min_bytes, m.bad.as<int32_t>(), totals + 2, n, st),
        "cub::DeviceReduce::Min");
  CountKernel<<<1, 1, 0, st>>>(m.kept.as<int32_t>(), m.at.as<int32_t>(), n, totals);
  LaunchKernel("WriteStreaksKernel", WriteStreaksKernel, blocks, kBlock, 0, st, d,
               m.kept.as<int32_t>(), m.at.as<int32_t>(), m.out.as<StreakCullOut>(),
               m.set_of.as<int32_t>(), m.pods.as<StreakPod>());
  // the counts back into page-locked memory (Finish reads them), then the event the frame's
  // stream waits for
  Check(cudaMemcpyAsync(m.totals_host.p, totals, sizeof(int32_t) * 3, cudaMemcpyDeviceToHost, st),
        "cudaMemcpyAsync");
  Check(cudaEventRecord(m.counted, st), "cudaEventRecord");
  Check(cudaEventRecord(m.done, st), "cudaEventRecord");
  if (wait_stream != nullptr)
    Check(cudaStreamWaitEvent(static_cast<cudaStream_t>(wait_stream), m.done, 0),
          "cudaStreamWaitEvent");
  m.pending = true;
  bound_ = n;
  run_ms_ =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace penumbra::cuda
