#include "penumbra/app/decompose_command.h"

#include <fmt/format.h>

#include <CLI/CLI.hpp>
#include <chrono>
#include <fstream>

#include "penumbra/core/error.h"
#include "penumbra/core/text_match.h"
#include "penumbra/decompose/concavity.h"
#include "penumbra/decompose/decomposition_cache.h"
#include "penumbra/decompose/mesh_io.h"
#include "penumbra/decompose/test_shapes.h"

namespace penumbra {
namespace {

void AddNumber(CLI::App* app, const std::string& name, double* target, double lo, double hi,
               const std::string& help) {
  const std::string range = fmt::format("a decimal number in [{}, {}]", lo, hi);
  app->add_option_function<std::string>(
         name, [target](const std::string& s) { *target = *ParseDecimal(s); }, help)
      ->type_name("NUM")
      ->check(CLI::Validator(
          [lo, hi, range](std::string& s) -> std::string {
            const std::optional<double> v = ParseDecimal(s);
            if (!v || !(*v >= lo && *v <= hi)) return "'" + s + "' is not " + range;
            return "";
          },
          range, ""));
}

void AddCount(CLI::App* app, const std::string& name, int* target, int lo, int hi,
              const std::string& help) {
  const std::string range = fmt::format("an integer in [{}, {}]", lo, hi);
  app->add_option_function<std::string>(
         name, [target](const std::string& s) { *target = std::stoi(s); }, help)
      ->type_name("INT")
      ->check(CLI::Validator(
          [lo, hi, range](std::string& s) -> std::string {
            if (s.empty() || s.size() > 9 || s.find_first_not_of("0123456789") != std::string::npos)
              return "'" + s + "' is not " + range;
            const int v = std::stoi(s);
            if (v < lo || v > hi) return "'" + s + "' is not " + range;
            return "";
          },
          range, ""));
}

void AddDecompositionOptions(CLI::App* app, DecompositionOptions* o, int* seed) {
  AddNumber(app, "--threshold", &o->concavity_threshold, 1e-4, 1,
            "concavity threshold, a fraction of the mesh's largest extent (default 0.025)");
  AddCount(app, "--max-parts", &o->max_parts, 1, 4096, "most parts (default 32)");
  AddCount(app, "--iterations", &o->mcts_iterations, 1, 100000,
           "tree search iterations per cut (default 60)");
  AddCount(app, "--depth", &o->mcts_depth, 1, 16, "tree search depth (default 3)");
  AddCount(app, "--search-samples", &o->search_samples, 16, 10000000,
           "surface samples of the concavity inside the search (default 600)");
  AddCount(app, "--seed", seed, 0, 1000000000, "search seed (default 0)");
}

double Seconds(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

int RunDecompose(const DecomposeCommandOptions& options) {
  DecomposeCommandOptions o = options;
  o.decomposition.method = ParseDecompositionMethod(o.method_name, "--method");
  o.decomposition.seed = static_cast<uint64_t>(o.seed);
  if (o.mesh_file.empty() == o.shape.empty())
    throw ConfigError("", 0, "mesh", "give a mesh file or --shape, not both and not neither");
  const std::string name = o.shape.empty() ? o.mesh_file : "shape " + o.shape;
  SolidMesh mesh = o.shape.empty() ? ReadMeshFile(o.mesh_file, o.scale) : MakeTestShape(o.shape);
  const auto t0 = std::chrono::steady_clock::now();
  CachedDecomposition result;
  if (o.no_cache) {
    result.decomposition = DecomposeMesh(mesh, o.decomposition, name);
  } else {
    const DecompositionCache cache(o.cache_dir.empty() ? DefaultDecompositionCacheDir()
                                                       : o.cache_dir);
    result = DecomposeCached(mesh, o.decomposition, cache, name);
  }
  const double seconds = Seconds(t0);
  const Decomposition& d = result.decomposition;
  fmt::print("{}: {} triangles, volume {:.6g} m^3, largest extent {:.4g} m\n", name,
             mesh.triangles.size(), d.mesh_volume, d.extent);
  fmt::print(
      "method {}: {} parts, {} cuts, max concavity {:.4g} m ({:.4f} of the extent, "
      "threshold {:.4f})\n",
      DecompositionMethodName(d.method), d.parts.size(), d.cuts, d.max_concavity,
      d.relative_max_concavity(), o.decomposition.concavity_threshold);
  fmt::print("hull volumes / mesh volume {:.4f}; {:.3f} s{}\n", d.HullVolumeSum() / d.mesh_volume,
             seconds,
             o.no_cache ? "" : (result.cache_hit ? " (cache hit)" : " (computed, cached)"));
  if (d.hit_cut_limit)
    fmt::print("note: the cut limit ended the search before every piece was under the threshold\n");
  if (d.hit_part_limit) fmt::print("note: --max-parts forced merges over the threshold\n");
  if (!o.obj_out.empty()) WritePartsObj(d, o.obj_out);
  if (!o.mjcf_out.empty()) {
    const PartsMjcf parts = PartsToMjcf(d, "part", "rgba=\"0.8 0.6 0.4 1\"");
    std::ofstream out(o.mjcf_out);
    out << "<mujoco model=\"decomposed\">\n  <asset>\n"
        << parts.assets << "  </asset>\n  <worldbody>\n    <body name=\"decomposed\">\n"
        << parts.geoms << "    </body>\n  </worldbody>\n</mujoco>\n";
    if (!out) throw Error(o.mjcf_out + ": cannot write");
  }
  return 0;
}

class DecomposeCommand : public Command {
 public:
  std::string name() const override { return "decompose"; }
  std::string summary() const override {
    return "convex decomposition of a closed mesh for collision (docs/collision.md)";
  }

  void AddOptions(CLI::App* verb) override {
    DecomposeCommandOptions& o = options_;
    verb->add_option("mesh", o.mesh_file, "closed mesh: .off .obj .stl .ply");
    verb->add_option("--shape", o.shape, "a generated test shape instead of a file")
        ->check(CLI::IsMember(TestShapeNames()));
    AddNumber(verb, "--scale", &o.scale, 1e-9, 1e9, "m per mesh file unit (default 1)");
    verb->add_option("--method", o.method_name, "coacd (default), hull or exact")
        ->check(CLI::IsMember({"coacd", "hull", "exact"}));
    AddDecompositionOptions(verb, &o.decomposition, &o.seed);
    verb->add_option("--obj", o.obj_out, "write the parts as OBJ (one object per part)");
    verb->add_option("--mjcf", o.mjcf_out, "write an MJCF model with one geom per part");
    verb->add_option("--cache-dir", o.cache_dir,
                     "cache folder (default $PENUMBRA_CACHE_DIR/decompose or "
                     "~/.cache/penumbra/decompose)");
    verb->add_flag("--no-cache", o.no_cache, "neither read nor write the cache");
  }

  int Run(const CommandArgs&) override { return RunDecompose(options_); }

 private:
  DecomposeCommandOptions options_;
};

class BenchDecomposeCommand : public Command {
 public:
  std::string name() const override { return "bench decompose"; }
  std::string summary() const override {
    return "CoACD vs convex hull vs CGAL exact decomposition on the test shapes";
  }

  void AddOptions(CLI::App* verb) override {
    verb->add_option("--shapes", options_.shapes, "test shapes (default all)")
        ->check(CLI::IsMember(TestShapeNames()))
        ->delimiter(',');
    verb->add_flag("!--no-exact", options_.exact, "skip CGAL's exact decomposition");
    AddDecompositionOptions(verb, &options_.decomposition, &options_.seed);
  }

  int Run(const CommandArgs&) override { return BenchDecompose(options_); }

 private:
  BenchDecomposeOptions options_;
};

}  // namespace

std::unique_ptr<Command> MakeDecomposeCommand() { return std::make_unique<DecomposeCommand>(); }
std::unique_ptr<Command> MakeBenchDecomposeCommand() {
  return std::make_unique<BenchDecomposeCommand>();
}

}  // namespace penumbra
