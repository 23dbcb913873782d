#include "penumbra/decompose/decomposition.h"

#include <fmt/format.h>

#include <algorithm>

#include "penumbra/core/error.h"
#include "penumbra/decompose/coacd.h"
#include "penumbra/decompose/convex_hull.h"
#include "penumbra/decompose/exact_decomposition.h"

namespace penumbra {

const char* DecompositionMethodName(DecompositionMethod method) {
  switch (method) {
    case DecompositionMethod::kCoacd:
      return "coacd";
    case DecompositionMethod::kHull:
      return "hull";
    case DecompositionMethod::kExact:
      return "exact";
  }
  return "?";
}

DecompositionMethod ParseDecompositionMethod(const std::string& name, const std::string& key) {
  if (name == "coacd") return DecompositionMethod::kCoacd;
  if (name == "hull") return DecompositionMethod::kHull;
  if (name == "exact") return DecompositionMethod::kExact;
  throw ConfigError("", 0, key, "unknown method '" + name + "'; expected coacd, hull or exact");
}

void DecompositionOptions::ValidateOrThrow() const {
  auto bad = [](const char* field, const std::string& what) {
    throw ConfigError("", 0, field, what);
  };
  if (!(concavity_threshold > 0 && concavity_threshold <= 1))
    bad("concavity_threshold", fmt::format("{} is out of range; expected (0, 1] (a fraction of "
                                           "the mesh's largest extent)",
                                           concavity_threshold));
  if (max_parts < 1 || max_parts > 4096)
    bad("max_parts", fmt::format("{} is out of range; expected 1..4096", max_parts));
  if (max_cuts < 0 || max_cuts > 100000)
    bad("max_cuts", fmt::format("{} is out of range; expected 0..100000", max_cuts));
  if (mcts_iterations < 1 || mcts_iterations > 100000)
    bad("mcts_iterations", fmt::format("{} is out of range; expected 1..100000", mcts_iterations));
  if (mcts_depth < 1 || mcts_depth > 16)
    bad("mcts_depth", fmt::format("{} is out of range; expected 1..16", mcts_depth));
  if (planes_per_axis < 1 || planes_per_axis > 1000)
    bad("planes_per_axis", fmt::format("{} is out of range; expected 1..1000", planes_per_axis));
  if (rollout_planes < 1 || rollout_planes > 1000)
    bad("rollout_planes", fmt::format("{} is out of range; expected 1..1000", rollout_planes));
  if (search_samples < 16 || search_samples > 10000000)
    bad("search_samples", fmt::format("{} is out of range; expected 16..10000000", search_samples));
  if (concavity.samples < 16 || concavity.samples > 10000000)
    bad("concavity.samples",
        fmt::format("{} is out of range; expected 16..10000000", concavity.samples));
  if (!(concavity.rv_k >= 0 && concavity.rv_k <= 10))
    bad("concavity.rv_k", fmt::format("{} is out of range; expected [0, 10]", concavity.rv_k));
}

double Decomposition::HullVolumeSum() const {
  double sum = 0;
  for (const ConvexPart& part : parts) sum += MeshVolume(part.hull);
  return sum;
}

Decomposition StartDecomposition(DecompositionMethod method, const SolidMesh& mesh) {
  Decomposition out;
  out.method = method;
  out.mesh_volume = MeshVolume(mesh);
  const auto bounds = MeshBounds(mesh);
  out.extent = (bounds[1] - bounds[0]).maxCoeff();
  return out;
}

Decomposition DecomposeHull(const SolidMesh& mesh, const DecompositionOptions& options) {
  Decomposition out = StartDecomposition(DecompositionMethod::kHull, mesh);
  ConvexPart part;
  part.hull = CanonicalMesh(ConvexHullOf(mesh.vertices));
  part.volume = out.mesh_volume;
  part.concavity = Concavity(mesh, part.volume, part.hull, options.concavity).value();
  out.max_concavity = part.concavity;
  out.parts.push_back(std::move(part));
  return out;
}

Decomposition DecomposeMesh(const SolidMesh& mesh, const DecompositionOptions& options,
                            const std::string& name) {
  options.ValidateOrThrow();
  ValidateClosedMesh(mesh, name);
  switch (options.method) {
    case DecompositionMethod::kHull:
      return DecomposeHull(mesh, options);
    case DecompositionMethod::kExact:
      return DecomposeExact(mesh, options);
    case DecompositionMethod::kCoacd:
      break;
  }
  return DecomposeCoacd(mesh, options);
}

}  // namespace penumbra
