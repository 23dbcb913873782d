#pragma once
// the one list of the `penumbra` verbs (app/command.h): RunCli builds the command line from it,
// in its order (the order of `penumbra --help`), and tests/app/command_list_test.cc checks that
// README.md's command-line block names every verb.

#include <memory>
#include <string>
#include <vector>

#include "penumbra/app/command.h"

namespace penumbra {

/// a word that groups verbs (`penumbra bench render`): its name and one-line summary.
struct CommandGroup {
  std::string name;
  std::string summary;
};

/// the groups of CommandList()'s verbs ("bench").
const std::vector<CommandGroup>& CommandGroups();

/// every verb of the command line, in the order of `penumbra --help`; new objects each call.
std::vector<std::unique_ptr<Command>> CommandList();

}  // namespace penumbra
