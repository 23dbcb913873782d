// the one list of verbs (app/command_list.h): README.md's command-line block names every verb
// and no other, and `penumbra --help` / `penumbra GROUP --help` list every verb with the
// summary of its Command.
#include "penumbra/app/command_list.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "app/child_process.h"
#include "common/temp_dir.h"

namespace penumbra {
namespace {

namespace fs = std::filesystem;

// the lines of README.md's "## Command line" block (its first fenced block)
std::vector<std::string> ReadmeCommandBlock() {
  std::ifstream in(fs::path(PENUMBRA_SOURCE_DIR) / "README.md");
  std::vector<std::string> block;
  std::string line;
  bool in_section = false, in_block = false;
  while (std::getline(in, line)) {
    if (!in_section) {
      in_section = line == "## Command line";
      continue;
    }
    if (line.rfind("```", 0) == 0) {
      if (in_block) break;
      in_block = true;
      continue;
    }
    if (in_block) block.push_back(line);
  }
  return block;
}

// the verb a block line shows ("penumbra bench render  [--world FILE]" -> "bench render"): the
// words after `penumbra` up to the first argument (upper case, an option, a path or a choice)
std::string VerbOfLine(const std::string& line, const std::set<std::string>& groups) {
  if (line.rfind("penumbra ", 0) != 0) return "";
  std::istringstream words(line);
  std::string word;
  words >> word;
  if (!(words >> word) || word.rfind("-", 0) == 0) return "";
  std::string verb = word;
  if (groups.count(word) && words >> word) verb += " " + word;
  return verb;
}

TEST(CommandListTest, TheReadmeCommandBlockNamesEveryVerbAndNoOther) {
  const std::vector<std::string> block = ReadmeCommandBlock();
  ASSERT_FALSE(block.empty()) << "README.md has no \"## Command line\" block";
  std::set<std::string> groups;
  for (const CommandGroup& g : CommandGroups()) groups.insert(g.name);
  std::set<std::string> documented;
  for (const std::string& line : block) {
    const std::string verb = VerbOfLine(line, groups);
    if (!verb.empty()) documented.insert(verb);
  }
  std::set<std::string> verbs;
  for (const std::unique_ptr<Command>& c : CommandList()) {
    EXPECT_TRUE(verbs.insert(c->name()).second) << "verb listed twice: " << c->name();
    EXPECT_TRUE(documented.count(c->name()))
        << "`penumbra " << c->name() << "` is not in README.md's command-line block";
    EXPECT_FALSE(c->summary().empty()) << c->name();
  }
  for (const std::string& verb : documented)
    EXPECT_TRUE(verbs.count(verb)) << "README.md's command-line block shows `penumbra " << verb
                                   << "`, which app/command_list.cc does not list";
  EXPECT_EQ(verbs.size(), 22u);
}

TEST(CommandListTest, HelpListsEveryVerbWithItsSummary) {
  const testing::TempDir dir;
  std::map<std::string, std::string> help;  // "" = top level, else the group's --help
  for (const std::unique_ptr<Command>& c : CommandList()) {
    const std::string name = c->name();
    const size_t space = name.find(' ');
    const std::string group = space == std::string::npos ? "" : name.substr(0, space);
    if (!help.count(group)) {
      std::vector<std::string> args;
      if (!group.empty()) args.push_back(group);
      args.push_back("--help");
      const testing::ProcessResult r = testing::RunPenumbra(args, dir.path());
      ASSERT_EQ(r.exit_code, 0) << r.err;
      help[group] = r.out;
    }
    const std::string word = space == std::string::npos ? name : name.substr(space + 1);
    // CLI11 lists a subcommand as "  WORD  SUMMARY" (the summary may wrap at its words)
    const std::string& text = help[group];
    EXPECT_NE(text.find("  " + word + " "), std::string::npos) << name << " in:\n" << text;
    const std::string summary = c->summary();
    EXPECT_NE(text.find(summary.substr(0, std::min<size_t>(summary.size(), 30))), std::string::npos)
        << name << "'s summary in:\n"
        << text;
  }
  for (const CommandGroup& g : CommandGroups())
    EXPECT_NE(help[""].find(g.summary), std::string::npos) << g.name;
}

}  // namespace
}  // namespace penumbra
