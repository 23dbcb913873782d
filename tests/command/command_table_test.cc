// the command table (CommandDispatcher::Commands): Dispatch finds every command through it, and
// it equals the table of docs/zmq-protocol.md "Commands" (names, when each is carried out,
// which are logged as "command" events), so the protocol document and the server cannot drift.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <map>
#include <regex>
#include <string>
#include <tuple>
#include <vector>

#include "common/temp_dir.h"
#include "penumbra/command/command_dispatcher.h"

namespace penumbra {
namespace {

using CommandRow = std::tuple<std::string, std::string, bool>;  // name, carried out, logged

std::string TimingWords(CommandDispatcher::CommandTiming t) {
  switch (t) {
    case CommandDispatcher::CommandTiming::kNow:
      return "at once";
    case CommandDispatcher::CommandTiming::kStepBoundary:
      return "step boundary";
    case CommandDispatcher::CommandTiming::kLive:
      return "live";
  }
  return "?";
}

// the rows of the table under "## Commands" in docs/zmq-protocol.md, but the bridges' own
std::vector<CommandRow> DocumentedCommandRows(const std::string& doc, std::string* bridge_rows) {
  const size_t start = doc.find("\n## Commands\n");
  const size_t end = doc.find("\n### ", start);
  if (start == std::string::npos || end == std::string::npos) return {};
  const std::string section = doc.substr(start, end - start);
  const std::regex row(R"(\n\| \[`([a-z_]+)`\]\(#[a-z_-]+\) \| ([^|]+?) \| (yes|no) \|)");
  std::vector<CommandRow> out;
  for (auto it = std::sregex_iterator(section.begin(), section.end(), row);
       it != std::sregex_iterator(); ++it) {
    const std::string when = (*it)[2];
    if (when.find("bridge") != std::string::npos) {
      *bridge_rows += std::string((*it)[1]) + " ";
      continue;
    }
    out.emplace_back((*it)[1], when, (*it)[3] == "yes");
  }
  return out;
}

TEST(CommandTable, EqualsTheProtocolDocument) {
  const std::string doc =
      testing::ReadAll(std::filesystem::path(PENUMBRA_SOURCE_DIR) / "docs" / "zmq-protocol.md");
  ASSERT_FALSE(doc.empty()) << "docs/zmq-protocol.md not found";
  std::string bridge_rows;
  const std::vector<CommandRow> documented = DocumentedCommandRows(doc, &bridge_rows);
  std::vector<CommandRow> table;
  for (const CommandDispatcher::CommandInfo& c : CommandDispatcher::Commands())
    table.emplace_back(std::string(c.name), TimingWords(c.timing), c.logged);
  EXPECT_EQ(documented, table) << "docs/zmq-protocol.md \"## Commands\" lists every command of "
                                  "CommandDispatcher::Commands() in its order, with when it is "
                                  "carried out and whether it is logged";
  // the ZeroMQ bridge's own command is documented beside them
  EXPECT_EQ(bridge_rows, "sync ");
}

TEST(CommandTable, IsSortedAndEveryRowHasAHandler) {
  const auto table = CommandDispatcher::Commands();
  ASSERT_EQ(table.size(), 18u);
  for (size_t i = 0; i < table.size(); ++i) {
    EXPECT_NE(table[i].handle, nullptr) << table[i].name;
    if (i > 0) {
      EXPECT_LT(table[i - 1].name, table[i].name);
    }
    EXPECT_EQ(CommandDispatcher::FindCommand(table[i].name), &table[i]);
  }
  EXPECT_EQ(CommandDispatcher::FindCommand("sync"), nullptr);
  EXPECT_EQ(CommandDispatcher::FindCommand("step "), nullptr);
  std::vector<std::string> names = CommandDispatcher::CommandNames();
  EXPECT_TRUE(std::is_sorted(names.begin(), names.end()));
  EXPECT_EQ(names.size(), table.size());
}

TEST(CommandTable, LogsExactlyTheCommandsThatChangeTheSimulation) {
  std::vector<std::string> logged;
  for (const CommandDispatcher::CommandInfo& c : CommandDispatcher::Commands())
    if (c.logged) logged.emplace_back(c.name);
  // docs/run-log.md "Events": the bridges' commands that change the simulation
  EXPECT_EQ(logged, (std::vector<std::string>{"joint_targets", "reset", "set_ctrl", "set_mocap",
                                              "twist", "waypoints"}));
}

}  // namespace
}  // namespace penumbra
