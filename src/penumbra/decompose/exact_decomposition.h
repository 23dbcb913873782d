#pragma once
// exact convex decomposition with CGAL (Nef_polyhedron_3 and convex_decomposition_3, after
// Chazelle's vertical-wall decomposition: every reflex edge is resolved by walls, so the parts
// are exactly convex and exactly cover the mesh, and curved (finely tessellated) concave
// surfaces give one part per facet strip). exact arithmetic (Epeck): slow; kept as the
// reference that `penumbra bench decompose` compares CoACD and the plain hull against.

#include "penumbra/decompose/decomposition.h"

namespace penumbra {

/// the convex parts of CGAL's exact decomposition, each with concavity 0 by construction
/// (measured all the same with the options' concavity measure). `mesh` must be closed.
Decomposition DecomposeExact(const SolidMesh& mesh, const DecompositionOptions& options);

}  // namespace penumbra
