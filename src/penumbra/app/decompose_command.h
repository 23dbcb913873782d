#pragma once
// `penumbra decompose MESH`: convex decomposition of a closed mesh for collision
// (decompose/, docs/collision.md), printed as a summary and written as OBJ parts and MJCF; and
// `penumbra bench decompose`: CoACD vs the plain convex hull vs CGAL's exact decomposition on
// the test shapes (parts, max concavity, hull volume over mesh volume, time). the bench is a
// benchmark, never a pass/fail test.

#include <memory>
#include <string>
#include <vector>

#include "penumbra/decompose/decomposition.h"

namespace CLI {
class App;
}

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

/// options of `penumbra bench decompose`.
struct BenchDecomposeOptions {
  std::vector<std::string> shapes = {"l", "u", "torus", "bowl"};
  bool exact = true;  ///< include CGAL's exact decomposition (slow)
  DecompositionOptions decomposition;
  int seed = 0;  ///< the search seed
};

/// both verbs as registered.
struct DecomposeCommands {
  CLI::App* decompose = nullptr;  ///< `penumbra decompose`
  CLI::App* bench = nullptr;      ///< `penumbra bench decompose`
  DecomposeCommandOptions options;
  BenchDecomposeOptions bench_options;
  /// runs `penumbra decompose`; prints the summary; returns 0.
  /// @throws Error for an unreadable or open mesh, ConfigError for bad options.
  int RunDecompose() const;
  /// runs the benchmark; prints the table; returns 0.
  int RunBench() const;
};

/// adds `decompose` to `app` and `decompose` to `bench` (the `penumbra bench` subcommand).
std::unique_ptr<DecomposeCommands> AddDecomposeCommands(CLI::App& app, CLI::App& bench);

}  // namespace penumbra
