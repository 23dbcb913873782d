#pragma once
// triangle meshes of the MuJoCo geoms that RayScene traces as triangles: box, mesh and
// height field, in the geom frame, counter-clockwise seen from outside (outward normals).

#include <Eigen/Core>
#include <vector>

#include "penumbra/scene/scene_description.h"

namespace penumbra {

/// an indexed triangle mesh with optional per-vertex normals and texcoords.
struct TriangleShape {
  std::vector<Eigen::Vector3f> vertices;  ///< (N) positions, geom frame, m
  std::vector<Eigen::Vector3f>
      normals;  ///< (N) unit vertex normals for smooth shading, or empty (flat)
  std::vector<Eigen::Vector2f> texcoords;  ///< (N) or empty
  std::vector<Eigen::Vector3i> faces;      ///< (F) vertex indices, counter-clockwise from outside
};

/// the 12 triangles of a box with half extents `half` (flat shaded).
TriangleShape BoxTriangles(const Eigen::Vector3d& half);

/// a mesh as given (normals / texcoords kept when there is one per vertex).
/// @throws Error if a face indexes a missing vertex.
TriangleShape MeshTriangles(const TriangleMesh& mesh);

/// a MuJoCo height field: the elevation grid (two triangles per cell, smooth vertex normals
/// from central differences), four side walls down to -size_base and the bottom face.
/// @throws Error if rows or cols < 2 or elevation.size() != rows cols.
TriangleShape HeightFieldTriangles(const HeightField& hf);

}  // namespace penumbra
