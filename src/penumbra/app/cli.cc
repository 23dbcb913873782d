#include "penumbra/app/cli.h"

#include <CLI/CLI.hpp>

namespace penumbra {

int RunCli(int argc, char** argv) {
  CLI::App app{"penumbra: robotics simulator with a physically based ray tracer"};
  app.require_subcommand(1);
  CLI11_PARSE(app, argc, argv);
  return 0;
}

}  // namespace penumbra
