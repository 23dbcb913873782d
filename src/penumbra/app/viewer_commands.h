#pragma once
// the live viewer's verbs (docs/viewer.md):
//   penumbra run WORLD --viewer [HOST:PORT]   a run served to browsers (viewer/viewer_bridge.h)
//   penumbra view WORLD [--viewer HOST:PORT]  the same at real-time pacing, paused at the start,
//                                             outputs in a temporary folder unless --out
//   penumbra bench viewer                     frames/s delivered, input-to-photon latency,
//                                             physics steps/s with and without a viewer
//                                             (the harness: bench/net/viewer_bench.h)

#include <atomic>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "penumbra/app/command.h"
#include "penumbra/run/runner.h"

namespace CLI {
class App;
}

namespace penumbra {

/// the `--viewer [HOST:PORT]` and `--viewer-allow-origin ORIGIN` flags of `penumbra run`.
struct ViewerFlag {
  std::string address;                     ///< as given ("" = the default 127.0.0.1:8080)
  std::vector<std::string> allow_origins;  ///< --viewer-allow-origin, repeatable
  /// adds the flags to `run`.
  void Add(CLI::App* run);
  /// adds the viewer bridge to options->bridges when --viewer was given on `run`.
  /// @throws ConfigError("", 0, "--viewer", ...) for a bad address or a missing web folder;
  ///         ConfigError("", 0, "--viewer-allow-origin", ...) for a bad origin or one given
  ///         without --viewer.
  void Apply(const CLI::App& run, RunOptions* options) const;
};

/// adds `--viewer-allow-origin ORIGIN` (repeatable) to a verb that starts the viewer.
void AddViewerAllowOrigin(CLI::App* verb, std::vector<std::string>* origins);

/// options of `penumbra view`.
struct ViewOptions {
  std::string address;                     ///< --viewer HOST:PORT ("" = 127.0.0.1:8080)
  std::vector<std::string> allow_origins;  ///< --viewer-allow-origin, repeatable
  /// --out: keep the outputs here ("" = a temporary folder, removed at exit unless it holds
  /// a recording made with the page's record button)
  std::string out_dir;
  bool running = false;                ///< --running: start running instead of paused
  bool force = false;                  ///< --force: --out may hold an earlier run's outputs
  std::optional<double> duration_sec;  ///< --duration (default: the world's)
  std::string adversity;               ///< --adversity preset spec
  std::vector<std::string> command_line;
};

/// `penumbra view`: runs `world` with the viewer at real-time pacing, paused at the start
/// unless options.running, until its duration ends or `stop_request` reads non-zero (Ctrl-C).
/// returns 0 (also when stopped by a signal: that is how a view ends).
/// @throws ConfigError for a bad address, world or output folder; Error when the port is in use.
int RunView(const WorldConfig& world, const ViewOptions& options,
            const std::atomic<int>* stop_request);

/// the `view` verb (app/command.h): RunView of a world file or model.
std::unique_ptr<Command> MakeViewCommand();
/// the `bench viewer` verb (app/command.h): BenchViewer.
std::unique_ptr<Command> MakeBenchViewerCommand();

}  // namespace penumbra
