#include "penumbra/app/command_list.h"

#include "penumbra/app/bench_commands.h"
#include "penumbra/app/benchmark_command.h"
#include "penumbra/app/compare_command.h"
#include "penumbra/app/decompose_command.h"
#include "penumbra/app/eval_command.h"
#include "penumbra/app/export_command.h"
#include "penumbra/app/replay_command.h"
#include "penumbra/app/run_command.h"
#include "penumbra/app/tool_commands.h"
#include "penumbra/app/viewer_commands.h"

namespace penumbra {

const std::vector<CommandGroup>& CommandGroups() {
  static const std::vector<CommandGroup> groups = {
      {"bench", "throughput benchmarks (not tests)"},
  };
  return groups;
}

std::vector<std::unique_ptr<Command>> CommandList() {
  std::vector<std::unique_ptr<Command>> list;
  list.push_back(MakeRunCommand());
  list.push_back(MakeBenchRenderCommand());
  list.push_back(MakeHeightfieldCommand());
  list.push_back(MakeContactSheetCommand());
  list.push_back(MakeNpcMapCommand());
  list.push_back(MakeMakeVdbCommand());
  list.push_back(MakeBenchPhysicsCommand());
  list.push_back(MakeBenchRecordCommand());
  list.push_back(MakeBenchBridgeCommand());
  list.push_back(MakeBenchRosCommand());
  list.push_back(MakeBenchRos2Command());
  list.push_back(MakeDecomposeCommand());
  list.push_back(MakeBenchDecomposeCommand());
  list.push_back(MakeBenchViewerCommand());
  list.push_back(MakeViewCommand());
  list.push_back(MakeBenchSensorsCommand());
  list.push_back(std::make_unique<EvalCommand>());
  list.push_back(MakeCompareCommand());
  list.push_back(std::make_unique<ExportCommand>());
  list.push_back(std::make_unique<ReplayCommand>());
  list.push_back(MakeBenchmarkCommand());
  list.push_back(MakeSlamCommand());
  return list;
}

}  // namespace penumbra
