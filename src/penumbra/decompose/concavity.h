#pragma once
// the collision-aware concavity of CoACD (Wei et al., SIGGRAPH 2022, section 4): how far a
// solid S is from its convex hull H, as the larger of
//   - the boundary term: the Hausdorff distance between the surface of S and the surface of
//     H, both directions, on deterministic area-weighted surface samples (points of S to the
//     hull boundary; points of H to the nearest point of S's surface), and
//   - the interior term R_v = k * (radius of the ball whose volume is vol(H) - vol(S)), which
//     catches cavities the surface samples miss.
// all distances in m. cut caps (SolidMesh::cut_faces) are left out of the S -> H samples:
// inside a merged part they are interior and would count as concavity that is not there.

#include <vector>

#include "penumbra/decompose/solid_mesh.h"

namespace penumbra {

/// sampling and weighting of the concavity measure.
struct ConcavityOptions {
  int samples = 2000;  ///< surface samples per direction (area-weighted, deterministic)
  double rv_k = 0.3;   ///< weight k of the interior (volume) term
};

/// the parts of the measure (m).
struct ConcavityValue {
  double boundary = 0;  ///< Hausdorff distance of the surfaces (sampled)
  double interior = 0;  ///< R_v term
  double value() const { return boundary > interior ? boundary : interior; }
};

/// concavity of `solid` against `hull` (its convex hull, or any convex mesh containing it).
/// `solid_volume` (m^3) is the volume of the material, passed separately so that a merged
/// part (several meshes concatenated) counts each piece once.
ConcavityValue Concavity(const SolidMesh& solid, double solid_volume, const SolidMesh& hull,
                         const ConcavityOptions& options);

/// `count` points on the surface of `mesh`, area-weighted and deterministic (a stratified
/// walk over the cumulative area with R2 low-discrepancy barycentric coordinates); triangles
/// flagged as cut are skipped when `skip_cut_faces`.
std::vector<Eigen::Vector3d> SurfaceSamples(const SolidMesh& mesh, int count, bool skip_cut_faces);

/// largest distance (m) from a point of any hull in `hulls` to the solid bounded by `mesh`
/// (0 for points inside it), over `samples_per_hull` surface samples per hull: how far the
/// collision geometry sticks out of the real object. `mesh` must be closed.
double HullExcessDistance(const std::vector<SolidMesh>& hulls, const SolidMesh& mesh,
                          int samples_per_hull);

}  // namespace penumbra
