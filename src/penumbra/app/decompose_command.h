#pragma once
// `penumbra decompose MESH`: convex decomposition of a closed mesh for collision
// (decompose/, docs/collision.md), printed as a summary and written as OBJ parts and MJCF; and
// `penumbra bench decompose`: CoACD vs the plain convex hull vs CGAL's exact decomposition on
// the test shapes, whose harness is bench/decompose_bench.h.

#include <memory>
#include <string>
#include <vector>

#include "penumbra/app/command.h"
#include "penumbra/bench/decompose_bench.h"
#include "penumbra/decompose/decomposition.h"

namespace penumbra {

/// options of `penumbra decompose`.
struct DecomposeCommandOptions {
  std::string mesh_file;              ///< the mesh (.off .obj .stl .ply), or "" with shape
  std::string shape;                  ///< a generated test shape (l, u, torus, bowl) instead
  double scale = 1.0;                 ///< m per mesh file unit
  std::string method_name = "coacd";  ///< coacd, hull or exact
  DecompositionOptions decomposition;
  int seed = 0;           ///< the search seed
  std::string obj_out;    ///< write the parts as OBJ here ("" = no)
  std::string mjcf_out;   ///< write an MJCF model of the parts here ("" = no)
  std::string cache_dir;  ///< cache folder ("" = DefaultDecompositionCacheDir())
  bool no_cache = false;  ///< compute, neither read nor write the cache
};

/// the `decompose` verb (app/command.h).
std::unique_ptr<Command> MakeDecomposeCommand();
/// the `bench decompose` verb (app/command.h).
std::unique_ptr<Command> MakeBenchDecomposeCommand();

}  // namespace penumbra
