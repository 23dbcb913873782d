#include "penumbra/bench/decompose_bench.h"

#include <fmt/format.h>

#include <chrono>
#include <cstdio>

#include "penumbra/decompose/concavity.h"
#include "penumbra/decompose/test_shapes.h"

namespace penumbra {
namespace {

double ElapsedSeconds(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace

int BenchDecompose(const BenchDecomposeOptions& bench_options) {
  DecompositionOptions base = bench_options.decomposition;
  base.seed = static_cast<uint64_t>(bench_options.seed);
  fmt::print(
      "convex decomposition: CoACD (threshold {:.4f} of the extent, max {} parts) vs "
      "convex hull vs CGAL exact (Nef)\n",
      base.concavity_threshold, base.max_parts);
  fmt::print(
      "max concavity: of the parts, over the mesh's largest extent; excess: how far the "
      "hulls stick out of the mesh, over the extent; volume: hull volumes / mesh volume\n");
  fmt::print("{:<6} {:>6} {:<6} {:>6} {:>14} {:>8} {:>8} {:>9}\n", "shape", "tris", "method",
             "parts", "max concavity", "excess", "volume", "time s");
  for (const std::string& shape : bench_options.shapes) {
    const SolidMesh mesh = MakeTestShape(shape);
    for (DecompositionMethod method :
         {DecompositionMethod::kCoacd, DecompositionMethod::kHull, DecompositionMethod::kExact}) {
      if (method == DecompositionMethod::kExact && !bench_options.exact) continue;
      DecompositionOptions o = base;
      o.method = method;
      const auto t0 = std::chrono::steady_clock::now();
      const Decomposition d = DecomposeMesh(mesh, o, shape);
      const double seconds = ElapsedSeconds(t0);
      std::vector<SolidMesh> hulls;
      for (const ConvexPart& p : d.parts) hulls.push_back(p.hull);
      const double excess = HullExcessDistance(hulls, mesh, 4000) / d.extent;
      fmt::print("{:<6} {:>6} {:<6} {:>6} {:>14.4f} {:>8.4f} {:>8.4f} {:>9.3f}\n", shape,
                 mesh.triangles.size(), DecompositionMethodName(method), d.parts.size(),
                 d.relative_max_concavity(), excess, d.HullVolumeSum() / d.mesh_volume, seconds);
      std::fflush(stdout);
    }
  }
  return 0;
}

}  // namespace penumbra
