#pragma once
// a closed triangle mesh (a solid) as the convex decomposition (decompose/) works on it: vertices
// in metres, triangles as vertex index triples in counter-clockwise order seen from outside
// (outward normals), and one flag per triangle that marks faces made by a cut (the caps that
// MeshClipper adds) as opposed to faces of the input surface.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace penumbra {

/// a triangle mesh: vertices (m), triangles (indices into vertices, outward orientation).
struct SolidMesh {
  std::vector<Eigen::Vector3d> vertices;
  std::vector<std::array<int, 3>> triangles;
  /// per triangle: 1 for a cap made by a cut, 0 for input surface; empty means all 0.
  std::vector<uint8_t> cut_faces;

  bool empty() const { return triangles.empty(); }
  /// whether triangle t is a cut cap.
  bool IsCutFace(size_t t) const { return !cut_faces.empty() && cut_faces[t] != 0; }
};

/// axis-aligned bounds of the vertices (min, max); both zero for an empty mesh.
std::array<Eigen::Vector3d, 2> MeshBounds(const SolidMesh& mesh);

/// enclosed volume (m^3) by the divergence theorem; positive for outward-oriented closed
/// meshes, negative when the orientation is inverted.
double MeshVolume(const SolidMesh& mesh);

/// total surface area (m^2).
double MeshArea(const SolidMesh& mesh);

/// checks that the mesh can be decomposed: at least 4 vertices and 1 triangle, finite
/// coordinates, indices in range, no degenerate index triple, every undirected edge shared by
/// exactly two triangles with opposite directions (closed, consistently oriented 2-manifold)
/// and a positive volume (outward normals).
/// @throws Error "<name>: <problem>" naming the first bad triangle or edge.
void ValidateClosedMesh(const SolidMesh& mesh, const std::string& name);

/// `soup` with vertices at bit-equal positions merged (numbered in first-use order) and the
/// triangles that merging made degenerate dropped: the triangles of a file or of several
/// meshes become one connected surface.
SolidMesh WeldVertices(const SolidMesh& soup);

/// `mesh` with unreferenced vertices dropped and indices renumbered in first-use order.
SolidMesh CompactMesh(const SolidMesh& mesh);

/// the meshes of the vertex-connected components of `mesh`, each compacted, ordered by their
/// first triangle.
std::vector<SolidMesh> ConnectedComponents(const SolidMesh& mesh);

/// `mesh` in a canonical order that depends only on its geometry: vertices sorted by
/// coordinates (x, then y, then z), each triangle rotated to start at its smallest index and
/// the triangles sorted; cut flags dropped. hull libraries may return the same hull in an
/// allocation-dependent order; canonical hulls keep results bit-identical run to run.
SolidMesh CanonicalMesh(const SolidMesh& mesh);

/// concatenation of meshes (vertices appended, indices shifted, cut flags kept).
SolidMesh ConcatenateMeshes(const std::vector<const SolidMesh*>& meshes);

}  // namespace penumbra
