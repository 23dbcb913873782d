// the realtime tier's row sums, exposure and film kernels (realtime_kernels.cuh), and
// DeviceFrameExposure (cuda_realtime.h).

#include <string>

#include "penumbra/render/cuda/realtime_kernels.cuh"

namespace penumbra::cuda {
namespace realtime {
namespace {

// one warp per row: lane k sums columns k, k + 32, ... in order, then a fixed butterfly.
// camera blockIdx.y of a batch (radiance and rows hold every camera's in turn).
__global__ void RowSumWarpKernel(const Float3* radiance, int width, int height, double* rows) {
  const int lane = threadIdx.x & 31;
  const int v = blockIdx.x * (blockDim.x / 32) + threadIdx.x / 32;
  if (v >= height) return;  // whole warps leave together
  radiance += static_cast<int64_t>(blockIdx.y) * width * height;
  rows += static_cast<int64_t>(blockIdx.y) * height;
  double sum = 0;
  for (int u = lane; u < width; u += 32) {
    const Float3& c = radiance[static_cast<int64_t>(v) * width + u];
    const float rgb[3] = {c.x, c.y, c.z};
    sum += LogLuminanceTerm(rgb, 1e-4);
  }
  for (int offset = 16; offset > 0; offset /= 2) sum += __shfl_xor_sync(kFullWarp, sum, offset);
  if (lane == 0) rows[v] = sum;
}

struct Exposure {
  float e[3];
};

// film_math.h's FrameExposure of a frame's `height` row sums (height <= kMaxDeviceExposureRows)
// by the calling block: its threads bring the rows into shared memory (height doubles), one
// thread adds them in row order.
__device__ void BlockExposure(const double* rows, int height, int64_t pixels,
                              const FilmExposurePod& film, const float gains[3],
                              DeviceExposure* out) {
  extern __shared__ double shared_rows[];
  for (int v = threadIdx.x; v < height; v += blockDim.x) shared_rows[v] = rows[v];
  __syncthreads();
  if (threadIdx.x != 0) return;
  DeviceExposure d;
  d.ev100 = FrameExposure(film, shared_rows, height, pixels, kMinLuminance, gains, d.e);
  *out = d;
}

__global__ void ExposureKernel(const double* rows, int height, int64_t pixels, FilmExposurePod film,
                               Exposure gains, DeviceExposure* out) {
  BlockExposure(rows, height, pixels, film, gains.e, out);
}

// ExposureKernel over a batch: block k makes camera k's exposure from its rows (camera-major,
// `height` each) with its own film.
__global__ void BatchExposureKernel(const double* rows, int height, int64_t pixels,
                                    const RealtimeBatchFilm* film, DeviceExposure* out) {
  const int k = blockIdx.x;
  BlockExposure(rows + static_cast<int64_t>(k) * height, height, pixels, film[k].exposure,
                film[k].white_balance_gains, out + k);
}

__global__ void DevelopKernel(const Float3* radiance, int64_t n, Exposure exposure, int filmic,
                              const uint8_t* lut, uint8_t* rgb) {
  const int64_t i = blockIdx.x * static_cast<int64_t>(blockDim.x) + threadIdx.x;
  if (i >= n) return;
  DevelopPixel(radiance[i], exposure.e, filmic != 0, lut, rgb + 3 * i);
}

// DevelopKernel with the exposure the device computed (ExposureKernel).
__global__ void DevelopDeviceExposureKernel(const Float3* radiance, int64_t n,
                                            const DeviceExposure* exposure, int filmic,
                                            const uint8_t* lut, uint8_t* rgb) {
  const int64_t i = blockIdx.x * static_cast<int64_t>(blockDim.x) + threadIdx.x;
  if (i >= n) return;
  const float e[3] = {exposure->e[0], exposure->e[1], exposure->e[2]};
  DevelopPixel(radiance[i], e, filmic != 0, lut, rgb + 3 * i);
}

// DevelopKernel over a batch: camera blockIdx.y's n pixels with its own film and the exposure
// the device computed (BatchExposureKernel).
__global__ void BatchDevelopKernel(const Float3* radiance, int64_t n, const RealtimeBatchFilm* film,
                                   const DeviceExposure* exposure, uint8_t* rgb) {
  const int64_t i = blockIdx.x * static_cast<int64_t>(blockDim.x) + threadIdx.x;
  if (i >= n) return;
  const RealtimeBatchFilm& c = film[blockIdx.y];
  const DeviceExposure& x = exposure[blockIdx.y];
  const float e[3] = {x.e[0], x.e[1], x.e[2]};
  const int64_t k = static_cast<int64_t>(blockIdx.y) * n + i;
  DevelopPixel(radiance[k], e, c.filmic != 0, c.lut, rgb + 3 * k);
}

}  // namespace

void LaunchRowSums(const Float3* radiance, int W, int H, int cameras, double* rows,
                   cudaStream_t stream) {
  LaunchKernel("RowSumWarpKernel", RowSumWarpKernel, dim3((H + 3) / 4, cameras), 128, 0, stream,
               radiance, W, H, rows);
}

void LaunchExposure(const double* rows, int height, int64_t pixels, const FilmExposurePod& film,
                    const float gains[3], DeviceExposure* out, cudaStream_t stream) {
  const Exposure g{{gains[0], gains[1], gains[2]}};
  LaunchKernel("ExposureKernel", ExposureKernel, 1, 256, sizeof(double) * height, stream, rows,
               height, pixels, film, g, out);
}

void LaunchDevelop(const Float3* radiance, int64_t n, const float e[3], int filmic,
                   const uint8_t* lut, uint8_t* rgb, cudaStream_t stream) {
  const Exposure x{{e[0], e[1], e[2]}};
  LaunchKernel("DevelopKernel", DevelopKernel, static_cast<unsigned>((n + 255) / 256), 256, 0,
               stream, radiance, n, x, filmic, lut, rgb);
}

void LaunchDevelop(const Float3* radiance, int64_t n, const DeviceExposure* exposure, int filmic,
                   const uint8_t* lut, uint8_t* rgb, cudaStream_t stream) {
  LaunchKernel("DevelopKernel", DevelopDeviceExposureKernel, static_cast<unsigned>((n + 255) / 256),
               256, 0, stream, radiance, n, exposure, filmic, lut, rgb);
}

void LaunchBatchExposure(const double* rows, int height, int64_t n, int count,
                         const RealtimeBatchFilm* film, DeviceExposure* exposure,
                         cudaStream_t stream) {
  LaunchKernel("BatchExposureKernel", BatchExposureKernel, count, 256, sizeof(double) * height,
               stream, rows, height, n, film, exposure);
}

void LaunchBatchDevelop(const Float3* radiance, int64_t n, int count, const RealtimeBatchFilm* film,
                        const DeviceExposure* exposure, uint8_t* rgb, cudaStream_t stream) {
  LaunchKernel("BatchDevelopKernel", BatchDevelopKernel,
               dim3(static_cast<unsigned>((n + 255) / 256), count), 256, 0, stream, radiance, n,
               film, exposure, rgb);
}

}  // namespace realtime

double DeviceFrameExposure(const FilmExposurePod& film, const std::vector<double>& rows,
                           int64_t pixels, const float white_balance_gains[3], float exposure[3]) {
  const int height = static_cast<int>(rows.size());
  if (rows.size() > static_cast<size_t>(kMaxDeviceExposureRows))
    throw Error("DeviceFrameExposure: " + std::to_string(rows.size()) + " rows, at most " +
                std::to_string(kMaxDeviceExposureRows));
  Buffer device_rows, out;
  device_rows.Upload(rows.data(), sizeof(double) * rows.size(), nullptr);
  out.Reserve(sizeof(realtime::DeviceExposure));
  realtime::LaunchExposure(device_rows.as<double>(), height, pixels, film, white_balance_gains,
                           out.as<realtime::DeviceExposure>(), nullptr);
  realtime::DeviceExposure d;
  out.Download(&d, sizeof(d), nullptr);
  Check(cudaStreamSynchronize(nullptr), "ExposureKernel");
  for (int c = 0; c < 3; ++c) exposure[c] = d.e[c];
  return d.ev100;
}

}  // namespace penumbra::cuda
