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

/// what smooth shading and texture mapping read of a triangle shape placed in an instance
/// frame by the rotation R_IG (geom to instance frame), written once for both backends
/// (RayScene's TriangleGeom, the CUDA backend's BvhScene TriangleShading).
struct TriangleShadingTerms {
  /// (N) the shape's vertex normals in the instance frame, (R_IG n).normalized(); empty when
  /// the shape has none (flat shading).
  std::vector<Eigen::Vector3f> normals_I;
  /// (F) per face when the shape has texcoords: sqrt(texcoord area / surface area), texcoord
  /// units per metre (SurfaceHit::uv_per_m; 0 for a face of no area); else empty.
  std::vector<float> uv_per_m;
  /// (F) per face when the shape has texcoords: the texcoord gradient in the geom frame, J with
  /// J e1 = duv1, J e2 = duv2, J n = 0 (e1, e2 the face's edges, n its normal;
  /// SurfaceHit::duv_dp_G), zero for a degenerate face; else empty.
  std::vector<Eigen::Matrix<float, 2, 3>> duv_dp_G;
};

/// the TriangleShadingTerms of `shape` (geom frame) in the frame that R_IG rotates it into.
TriangleShadingTerms ShadingTermsOf(const TriangleShape& shape, const Eigen::Matrix3f& R_IG);

}  // namespace penumbra
