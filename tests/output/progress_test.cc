#include "penumbra/output/progress.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <string>
#include <vector>

namespace penumbra {
namespace {

TEST(FormatProgressLine, MatchesTheDocumentedLayout) {
  EXPECT_EQ(FormatProgressLine(4.5, 10.0, 123, 31.2, 10),
            "[####      ]  45% sim 4.50/10.00 s  123 frames  31.2 fps");
  EXPECT_EQ(FormatProgressLine(0.0, 10.0, 0, 0.0, 4),
            "[    ]   0% sim 0.00/10.00 s  0 frames  0.0 fps");
  EXPECT_EQ(FormatProgressLine(10.0, 10.0, 300, 30.0, 4),
            "[####] 100% sim 10.00/10.00 s  300 frames  30.0 fps");
  // past the end and zero durations clamp to 100 %
  EXPECT_NE(FormatProgressLine(12.0, 10.0, 1, 1, 4).find("[####] 100%"), std::string::npos);
  EXPECT_NE(FormatProgressLine(0.0, 0.0, 1, 1, 4).find("100%"), std::string::npos);
}

TEST(FormatProgressLine, BelowOneFramePerSecondItReadsSecondsPerFrame) {
  // one pathtraced frame in 160 s read "0.0 fps" before
  EXPECT_EQ(FormatProgressLine(0.1, 10.0, 1, 1.0 / 160.0, 4),
            "[    ]   1% sim 0.10/10.00 s  1 frames  160.0 s/frame");
  EXPECT_NE(FormatProgressLine(0.1, 10.0, 1, 1.0, 4).find("1.0 fps"), std::string::npos);
}

TEST(ProgressReporter, SamplePassLinesCarryAnEtaAndAreRateLimited) {
  EXPECT_EQ(ProgressReporter::FormatPassLine("camera 'c' frame 2", 1, 4, 40.0),
            "camera 'c' frame 2: sample pass 1/4 (25%), 40.0 s, ETA 120.0 s");
  std::vector<std::string> lines;
  double now = 0;
  ProgressOptions opt;
  opt.mode = ProgressOptions::Mode::kLog;
  opt.clock = [&] { return now; };
  opt.log = [&](const std::string& s) { lines.push_back(s); };
  opt.pass_interval_sec = 1.0;
  ProgressReporter p(10.0, opt);
  // a fast frame (0.3 s for 4 passes): no line
  for (int pass = 0; pass <= 4; ++pass) {
    now = 0.075 * pass;
    p.RenderPass("f0", pass, 4);
  }
  EXPECT_TRUE(lines.empty());
  // a slow one starting at 10 s: passes at +0.5 (too early), +1.2 (line), +1.5 (too soon
  // after it), +1.8 (the last pass of a frame that had a line: line)
  now = 10;
  p.RenderPass("f1", 0, 4);
  for (const auto& [t, pass] : {std::pair{10.5, 1}, {11.2, 2}, {11.5, 3}, {11.8, 4}}) {
    now = t;
    p.RenderPass("f1", pass, 4);
  }
  ASSERT_EQ(lines.size(), 2u);
  EXPECT_EQ(lines[0], "f1: sample pass 2/4 (50%), 1.2 s, ETA 1.2 s");
  EXPECT_EQ(lines[1], "f1: sample pass 4/4 (100%), 1.8 s, ETA 0.0 s");
  // interval 0: every pass
  lines.clear();
  opt.pass_interval_sec = 0;
  ProgressReporter every(10.0, opt);
  for (int pass = 0; pass <= 3; ++pass) every.RenderPass("f", pass, 3);
  EXPECT_EQ(lines.size(), 3u);
  // off: nothing
  lines.clear();
  opt.mode = ProgressOptions::Mode::kOff;
  ProgressReporter off(10.0, opt);
  for (int pass = 0; pass <= 3; ++pass) off.RenderPass("f", pass, 3);
  EXPECT_TRUE(lines.empty());
}

TEST(FormatProgressLine, PercentRoundsDown) {
  // 99.96 % must not print as 100 % before the end
  EXPECT_NE(FormatProgressLine(9.996, 10.0, 0, 0, 10).find(" 99%"), std::string::npos);
}

TEST(ProgressReporter, LogModeWritesOneLinePerTenPercent) {
  std::vector<std::string> lines;
  double now = 0;
  ProgressOptions opt;
  opt.mode = ProgressOptions::Mode::kLog;
  opt.clock = [&] { return now; };
  opt.log = [&](const std::string& s) { lines.push_back(s); };
  {
    ProgressReporter p(10.0, opt);
    EXPECT_EQ(p.mode(), ProgressOptions::Mode::kLog);
    for (int step = 1; step <= 1000; ++step) {  // 10 ms of sim per update, 1 ms wall
      now = 0.001 * step;
      p.Update(0.01 * step, step / 10);
    }
    p.Finish();
    p.Finish();  // idempotent
  }
  ASSERT_EQ(lines.size(), 10u);
  EXPECT_NE(lines[0].find(" 10% sim 1.00/10.00 s"), std::string::npos) << lines[0];
  EXPECT_NE(lines[9].find("100% sim 10.00/10.00 s  100 frames  100.0 fps"), std::string::npos)
      << lines[9];
}

TEST(ProgressReporter, LogModeFinishReportsAnUnfinishedRun) {
  std::vector<std::string> lines;
  ProgressOptions opt;
  opt.mode = ProgressOptions::Mode::kLog;
  opt.clock = [] { return 0.0; };
  opt.log = [&](const std::string& s) { lines.push_back(s); };
  {
    ProgressReporter p(10.0, opt);
    p.Update(3.5, 7);
  }  // destructor finishes
  // crossing 10, 20 and 30 % in one update logs one line; Finish adds the final state
  ASSERT_EQ(lines.size(), 2u);
  EXPECT_NE(lines[0].find(" 35% sim 3.50/10.00 s  7 frames"), std::string::npos) << lines[0];
  EXPECT_EQ(lines[1], lines[0]);
}

TEST(ProgressReporter, BarModeRedrawsAtMostTenTimesPerSecond) {
  std::FILE* f = std::tmpfile();
  ASSERT_NE(f, nullptr);
  double now = 100.0;
  ProgressOptions opt;
  opt.mode = ProgressOptions::Mode::kBar;
  opt.stream = f;
  opt.bar_width = 10;
  opt.clock = [&] { return now; };
  {
    ProgressReporter p(10.0, opt);
    for (int step = 1; step <= 1000; ++step) {  // 2 s of wall time in 2 ms steps
      now = 100.0 + 0.002 * step;
      p.Update(0.01 * step, step);
    }
  }
  std::rewind(f);
  std::string out;
  char buf[4096];
  size_t n;
  while ((n = std::fread(buf, 1, sizeof(buf), f)) > 0) out.append(buf, n);
  std::fclose(f);
  const auto redraws = std::count(out.begin(), out.end(), '\r');
  EXPECT_GE(redraws, 20);  // 2 s at 10 per second, plus the final draw
  EXPECT_LE(redraws, 22);
  ASSERT_FALSE(out.empty());
  EXPECT_EQ(out.back(), '\n');
  const auto last = out.substr(out.rfind('\r') + 1);
  EXPECT_EQ(last, "[##########] 100% sim 10.00/10.00 s  1000 frames  500.0 fps\n");
}

}  // namespace
}  // namespace penumbra

namespace penumbra {
namespace {

TEST(ProgressReporter, AutoModeLogsWhenTheStreamIsNotATerminal) {
  std::FILE* f = std::tmpfile();
  ASSERT_NE(f, nullptr);
  std::vector<std::string> lines;
  ProgressOptions opt;
  opt.stream = f;
  opt.log = [&](const std::string& s) { lines.push_back(s); };
  {
    ProgressReporter p(1.0, opt);
    EXPECT_EQ(p.mode(), ProgressOptions::Mode::kLog);
    p.Update(1.0, 10);
  }
  EXPECT_EQ(lines.size(), 1u);
  EXPECT_EQ(std::ftell(f), 0L) << "nothing drawn on a non-terminal";
  std::fclose(f);
}

TEST(ProgressReporter, OffModeIsSilent) {
  std::vector<std::string> lines;
  ProgressOptions opt;
  opt.mode = ProgressOptions::Mode::kOff;
  opt.log = [&](const std::string& s) { lines.push_back(s); };
  {
    ProgressReporter p(1.0, opt);
    p.Update(0.5, 1);
    p.Update(1.0, 2);
  }
  EXPECT_TRUE(lines.empty());
}

}  // namespace
}  // namespace penumbra
