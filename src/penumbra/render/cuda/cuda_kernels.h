#pragma once
// the CUDA backend's device side, behind a plain-struct interface (no Eigen, no CUDA headers
// here, so that the classes calling it build with the host compiler): device probe, device
// copies of a BvhScene's arrays, and the kernels that run bvh_traversal.h on the GPU.
// implemented in cuda_kernels.cu. every function throws penumbra::Error naming the CUDA call
// and its message when the runtime reports an error.

#include <cstdint>
#include <functional>
#include <string>

#include "penumbra/render/bvh/bvh_types.h"
#include "penumbra/render/transport/primary_pixel.h"

namespace penumbra::cuda {

/// the process's first CUDA call, once (std::call_once): initialises the runtime and, where a
/// device is present, makes its context with every kernel of the process loaded in one order
/// (module loading EAGER: NVIDIA's CUDA Programming Guide, "Lazy Loading"), then leaves the
/// environment as it was. with lazy loading (the runtime's default since CUDA 12.2) a LiDAR's
/// CudaRayQuery, or a terrain ray caster, that traced before a renderer's first frame made
/// that renderer's realtime kernels 3-7 % slower for the whole run (about 17 us a frame;
/// docs/gpu.md, "Eager module loading"). CUDA_MODULE_LOADING set in the environment is kept as
/// it is (the user's choice); otherwise it is set to EAGER only during this call, so child
/// processes (e.g. a campaign's SLAM methods) do not inherit it. ProbeDevice and the device
/// classes' constructors (DeviceScene, the batch's device) call it; call it before any other
/// CUDA call of the process (from one thread: it changes the environment). never throws.
void InitRuntime();

/// true if a CUDA device can be used (cudaGetDeviceCount succeeds with >= 1 device); else
/// false, with the runtime's message in *why (e.g. "CUDA driver version is insufficient for
/// CUDA runtime version" on a machine without a GPU driver). *name: the first device's name.
bool ProbeDevice(std::string* name, std::string* why);

/// ExpRn (core/exp_rn.h) of the n floats x evaluated on the device into y (host arrays of n):
/// the shared exponential's device bits, which the tests compare with the host's.
/// @throws Error on a CUDA failure.
void ExpRnOnDevice(const float* x, float* y, int64_t n);

/// runs body(0) .. body(count - 1), in any order and possibly at once (a thread pool); the
/// renderers pass their pool's ParallelFor so that the host copies outputs on all its threads.
using ParallelFn = std::function<void(int64_t count, const std::function<void(int64_t)>& body)>;

/// RenderPrimary's images go back in this many bands of rows, the host copying band k into the
/// caller's buffers while band k + 1 comes back; a frame whose images hold at most
/// kPrimarySerialBytes goes back in one band and is copied on the calling thread alone (waking
/// the pool costs more than such copies).
constexpr int kPrimaryBands = 4;
constexpr size_t kPrimarySerialBytes = size_t{512} << 10;

/// where RenderPrimary's time went, milliseconds (benchmarks).
struct PrimaryTimes {
  double kernel = 0;  ///< CUDA events: from before the kernel to its end
  double copies = 0;  ///< CUDA events: from the same start to the last copy's end
  double total = 0;   ///< host clock: the whole call, the host's copies included
};

/// host buffers a primary render fills (null = not wanted), each width x height (x 3 for
/// normals), row-major: as RenderedFrame's depth_m, geom_id, range_m, normal_O, body_id,
/// semantic_class (primary_pixel.h's planes, here in host memory).
using PrimaryOutputs = PixelTruthPlanes;

/// a base of the device classes (DeviceScene, DeviceRealtime, ...): they own device memory,
/// streams and events, so they are neither copied nor assigned.
class NonCopyable {
 public:
  NonCopyable(const NonCopyable&) = delete;
  NonCopyable& operator=(const NonCopyable&) = delete;

 protected:
  NonCopyable() = default;
  ~NonCopyable() = default;
};

/// the device copy of a BvhScene, its staging buffers and a stream.
class DeviceScene : NonCopyable {
 public:
  DeviceScene();
  ~DeviceScene();

  /// the sizes of a SceneView's arrays.
  struct Sizes {
    int64_t nodes = 0, prims = 0, triangles = 0, analytics = 0, blases = 0, records = 0;
    int64_t shading = 0;  ///< TriangleShading records (0: none, SceneView::shading null)
  };
  /// copies the arrays of `view` (host pointers) to the device: all of them when
  /// geometry_version differs from the last call's, else the instances only. `wait`: returns
  /// when the copies are done; else once they are queued on stream() (the host arrays may
  /// change at once: they are staged), for callers whose kernels run on stream() after them.
  void Sync(const SceneView& view, const Sizes& sizes, int64_t geometry_version, bool wait = true);
  /// closest hits of n rays (host arrays).
  void Trace(const TraceRay* rays, int64_t n, TraceHit* hits);
  /// occlusion of n rays (host arrays): occluded[i] = 1 if blocked.
  void Occluded(const TraceRay* rays, int64_t n, uint8_t* occluded);
  /// one camera's primary rays: the ground-truth images of `out`, copied back to page-locked
  /// staging in kPrimaryBands bands of rows, then by the host into `out` in 256 KiB chunks
  /// (over `parallel` when it is given).
  void RenderPrimary(const PinholeCamera& camera, const PrimaryOutputs& out,
                     const ParallelFn& parallel = {});
  /// the stages of the last RenderPrimary.
  const PrimaryTimes& last_primary_times() const;
  /// `count` renders of `camera` into device memory only (no copy back), timed with CUDA
  /// events: the mean milliseconds per frame (benchmarks).
  double TimePrimary(const PinholeCamera& camera, int count, bool depth_and_seg_only);
  /// device copies of a camera's ray tables (camera_rays.h; host arrays of xy_floats and
  /// row_floats floats, either may be 0) on stream(): xy again only when xy_version differs from
  /// the last call's, rows every call; *xy_device and *rows_device get the device arrays (null
  /// for an empty table), valid until the next call.
  void UploadCameraRays(const float* xy, int64_t xy_floats, int64_t xy_version, const float* rows,
                        int64_t row_floats, const float** xy_device, const float** rows_device);
  /// the device arrays as the kernels read them (after Sync), and the stream every copy and
  /// kernel of this scene runs on (a cudaStream_t).
  const SceneView& device_view() const;
  void* stream() const;

 private:
  struct Impl;
  Impl* impl_;
};

}  // namespace penumbra::cuda
