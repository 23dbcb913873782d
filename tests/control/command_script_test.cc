// the reusable command source (control/command_script.h): scripted commands from a
// world-file block, the thread-safe queue, and the script parser's errors.

#include "penumbra/control/command_script.h"

#include <gtest/gtest.h>

#include <atomic>
#include <thread>

#include "penumbra/config/yaml_document.h"
#include "penumbra/core/error.h"

namespace penumbra {
namespace {

struct Cmd {
  int id = 0;
  double value = 0;
};

ControllerContext Context() { return {"world.yaml", 12, "robots[arm].controller"}; }

// a command of the test: {t, id, value}
std::vector<TimedCommand<Cmd>> Parse(const std::string& yaml) {
  ControllerParams p(ParseYaml(yaml), Context());
  auto script = ParseCommandScript<Cmd>(p, "commands", [](ParamNode& n) {
    Cmd c;
    c.id = static_cast<int>(n.Number("id", std::nullopt, 0, 100));
    c.value = n.Number("value", 0, -1e9, 1e9);
    return c;
  });
  p.CheckNoUnknownKeys();
  return script;
}

std::string ParseError(const std::string& yaml) {
  try {
    Parse(yaml);
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "";
}

std::vector<int> PollIds(CommandSource<Cmd>& s, double t) {
  std::vector<int> ids;
  s.Poll(t, [&](const Cmd& c) { ids.push_back(c.id); });
  return ids;
}

TEST(CommandScript, ParsesTimedItemsInOrder) {
  const auto script = Parse(
      "commands:\n"
      "  - {t: 0, id: 1}\n"
      "  - {t: 0.5, id: 2, value: -3}\n"
      "  - {t: 0.5, id: 3}\n");
  ASSERT_EQ(script.size(), 3u);
  EXPECT_EQ(script[1].time_sec, 0.5);
  EXPECT_EQ(script[1].command.id, 2);
  EXPECT_EQ(script[1].command.value, -3);
}

TEST(CommandScript, AbsentScriptIsEmpty) {
  ControllerParams p(ParseYaml("{}"), Context());
  EXPECT_TRUE(ParseCommandScript<Cmd>(p, "commands", [](ParamNode&) { return Cmd{}; }).empty());
}

TEST(CommandScript, ErrorsNameTheItemAndWhatWasExpected) {
  EXPECT_EQ(ParseError("commands: {t: 0}\n"),
            "world.yaml:12: robots[arm].controller.commands: expected a list of timed commands, "
            "e.g. [{t: 0.0, ...}, {t: 1.5, ...}]");
  EXPECT_NE(ParseError("commands: [5]\n").find("commands[0]: expected a mapping"),
            std::string::npos);
  EXPECT_NE(ParseError("commands: [{id: 1}]\n").find("commands[0].t: missing"), std::string::npos);
  EXPECT_NE(ParseError("commands: [{t: -1, id: 1}]\n").find("commands[0].t: got -1"),
            std::string::npos);
  EXPECT_NE(ParseError("commands: [{t: 2, id: 1}, {t: 1, id: 2}]\n")
                .find("commands[1].t: got 1 s after 2 s at commands[0]"),
            std::string::npos);
  const std::string unknown = ParseError("commands: [{t: 0, id: 1, vlaue: 2}]\n");
  EXPECT_NE(unknown.find("commands[0].vlaue: unknown key(s) 'vlaue'; expected only: id, t, value"),
            std::string::npos)
      << unknown;
  EXPECT_NE(ParseError("commands: [{t: 0, id: [1, 2]}]\n").find("commands[0].id: got a list"),
            std::string::npos);
}

TEST(CommandSource, ScriptThenQueueAtTheirTimes) {
  CommandSource<Cmd> s(
      Parse("commands:\n"
            "  - {t: 0, id: 1}\n"
            "  - {t: 0.5, id: 2}\n"
            "  - {t: 1.0, id: 3}\n"));
  s.Push({10, 0});       // due at once
  s.Push({11, 0}, 0.7);  // due at 0.7 s
  EXPECT_EQ(s.queued(), 2u);
  EXPECT_EQ(PollIds(s, 0.0), (std::vector<int>{1, 10}));
  EXPECT_EQ(PollIds(s, 0.25), std::vector<int>{});
  // sums of timesteps land just short of round times
  EXPECT_EQ(PollIds(s, 0.5 - 1e-12), std::vector<int>{2});
  EXPECT_EQ(PollIds(s, 0.69), std::vector<int>{});
  EXPECT_EQ(PollIds(s, 2.0), (std::vector<int>{3, 11}));
  EXPECT_EQ(s.script_position(), 3u);
  EXPECT_EQ(s.queued(), 0u);
  s.Rewind();
  EXPECT_EQ(PollIds(s, 0.6), (std::vector<int>{1, 2}));
}

TEST(CommandSource, SetReplacesTheQueueAndClearDropsIt) {
  CommandSource<Cmd> s;
  s.Push({1, 0}, 5.0);
  s.Push({2, 0}, 5.0);
  s.Set({3, 0});
  EXPECT_EQ(s.queued(), 1u);
  EXPECT_EQ(PollIds(s, 0), std::vector<int>{3});
  s.Push({4, 0});
  s.ClearQueue();
  EXPECT_EQ(PollIds(s, 10), std::vector<int>{});
}

// several threads push while the owner polls: every command arrives exactly once, and the
// commands of one thread arrive in its push order
TEST(CommandSource, ConcurrentPushesArriveOnceInOrder) {
  CommandSource<Cmd> s;
  constexpr int kThreads = 4, kPerThread = 2000;
  std::atomic<bool> go{false};
  std::vector<std::thread> threads;
  for (int k = 0; k < kThreads; ++k)
    threads.emplace_back([&, k] {
      while (!go.load()) {
      }
      for (int i = 0; i < kPerThread; ++i) s.Push({k, static_cast<double>(i)});
    });
  go = true;
  std::vector<int> next(kThreads, 0);
  int received = 0;
  bool in_order = true;
  auto poll = [&] {
    s.Poll(0, [&](const Cmd& c) {
      in_order &= static_cast<int>(c.value) == next[c.id];
      ++next[c.id];
      ++received;
    });
  };
  while (received < kThreads * kPerThread / 2) poll();
  for (auto& t : threads) t.join();
  poll();
  EXPECT_EQ(received, kThreads * kPerThread);
  EXPECT_TRUE(in_order);
}

}  // namespace
}  // namespace penumbra
