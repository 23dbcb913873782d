#include "penumbra/app/cli.h"

#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>

#include <CLI/CLI.hpp>
#include <iostream>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "penumbra/app/command_list.h"
#include "penumbra/app/stop_signals.h"
#include "penumbra/core/build_info.h"
#include "penumbra/core/error.h"
#include "penumbra/core/text_match.h"

namespace penumbra {
namespace {

// an empty value ("") given to an option that takes one, e.g. `--out ""`: refused instead of
// falling back to the default (options whose value is optional, `--zmq`, are skipped: CLI11
// records their bare form as "" too). walks the subcommands that were parsed.
void RefuseEmptyValues(const CLI::App& app) {
  for (const CLI::Option* o : app.get_options()) {
    if (o->count() == 0 || o->get_expected_min() < 1) continue;
    for (const std::string& v : o->results()) {
      if (!v.empty()) continue;
      const std::string name = o->get_name();
      throw ConfigError(
          "", 0, name,
          "an empty value; expected a non-empty " +
              std::string(o->nonpositional() ? "value (leave " + name + " out for its default)"
                                             : "argument"));
    }
  }
  for (const CLI::App* sub : app.get_subcommands()) RefuseEmptyValues(*sub);
}

// errors and logs go to stderr; stdout carries only what was asked for (--help, --version)
void LogToStderr() {
  auto logger =
      std::make_shared<spdlog::logger>("", std::make_shared<spdlog::sinks::stderr_color_sink_mt>());
  spdlog::set_default_logger(std::move(logger));
}

}  // namespace

int RunCli(int argc, char** argv) {
  LogToStderr();
  CLI::App app{
      "penumbra: robotics simulator with MuJoCo physics and a physically based ray tracer"};
  app.require_subcommand(1);
  app.set_version_flag("--version", std::string(PENUMBRA_VERSION));

  // the verbs of app/command_list.h, in its order: a group word ("bench") becomes a subcommand
  // of its own, with its summary from CommandGroups(), when its first verb comes
  const std::vector<std::unique_ptr<Command>> commands = CommandList();
  std::map<std::string, CLI::App*> groups;
  std::vector<CLI::App*> verbs;
  for (const std::unique_ptr<Command>& command : commands) {
    const std::string name = command->name();
    const size_t space = name.find(' ');
    CLI::App* parent = &app;
    if (space != std::string::npos) {
      const std::string group = name.substr(0, space);
      CLI::App*& g = groups[group];
      if (!g) {
        std::string summary;
        for (const CommandGroup& known : CommandGroups())
          if (known.name == group) summary = known.summary;
        g = app.add_subcommand(group, summary);
        g->require_subcommand(1);
      }
      parent = g;
    }
    CLI::App* verb = parent->add_subcommand(name.substr(space == std::string::npos ? 0 : space + 1),
                                            command->summary());
    command->AddOptions(verb);
    verbs.push_back(verb);
  }

  // usage errors exit 2 with CLI11's message on stderr; --help and --version print to stdout
  // and exit 0
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e, std::cout, std::cerr);
    return code == 0 ? 0 : 2;
  }

  try {
    RefuseEmptyValues(app);
    CommandArgs args;
    args.command_line = std::vector<std::string>(argv, argv + argc);
    args.stop_signal = &StopSignal();
    for (size_t i = 0; i < commands.size(); ++i)
      if (verbs[i]->parsed()) return commands[i]->Run(args);
  } catch (const ConfigError& e) {
    spdlog::error("{}", e.what());
    return 2;
  } catch (const std::bad_alloc&) {
    spdlog::error(
        "out of memory; expected smaller images, fewer cameras or LiDAR columns "
        "(docs/world-file.md \"Input limits\")");
    return 1;
  } catch (const std::exception& e) {
    // bounded: a message may quote input (a 100 KB name in a path)
    spdlog::error("{}", SanitizeForMessage(e.what(), 2048));
    return 1;
  }
  return 0;
}

}  // namespace penumbra
