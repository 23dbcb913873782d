// the state table (scene/sim_state.h kStateFields) is the run log's step record: docs/run-log.md
// lists the fields in table order with their sizes, and a record's bytes are the fields in that
// order (a log written before the table existed, with its hand-written field list, reads the
// same), so a change of the table that would break old logs fails here.
#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <regex>
#include <string>
#include <type_traits>
#include <vector>

#include "common/temp_dir.h"
#include "penumbra/runlog/run_log_codec.h"

namespace penumbra {
namespace {

// "nq", "3 nmocap", "controllers": the size column of docs/run-log.md for a field
std::string DocumentedSize(const StateFieldInfo& f) {
  const std::string dim = f.dim == StateDim::kNumControllers
                              ? "controllers"
                              : std::string(kStateDimNames[static_cast<size_t>(f.dim)]);
  return f.per == 1 ? dim : std::to_string(f.per) + " " + dim;
}

TEST(StateTable, RunLogDocumentListsTheFieldsInTableOrder) {
  const std::string doc =
      testing::ReadAll(std::filesystem::path(PENUMBRA_SOURCE_DIR) / "docs" / "run-log.md");
  ASSERT_FALSE(doc.empty()) << "docs/run-log.md not found";
  const size_t start = doc.find("\n## What is recorded\n");
  ASSERT_NE(start, std::string::npos);
  const size_t end = doc.find("\n\n", doc.find("| --- |", start));
  const std::string section = doc.substr(start, end - start);
  const std::regex row(R"(\n\| `([a-z_]+)` \| ([a-z0-9 ]+) \|)");
  std::vector<std::string> documented;
  for (auto it = std::sregex_iterator(section.begin(), section.end(), row);
       it != std::sregex_iterator(); ++it)
    documented.push_back(std::string((*it)[1]) + ": " + std::string((*it)[2]));
  std::vector<std::string> table = {"step: i64", "time_sec: f64"};
  for (const StateFieldInfo& f : kStateFields)
    table.push_back(std::string(f.name) + ": " + DocumentedSize(f));
  EXPECT_EQ(documented, table);
}

// the bytes of one record as docs/run-log.md "Steps chunk" spells them out, written by hand in
// the order of format version 1 (independent of the table): step, time, then per field an
// encoding byte, a u32 count and the words
std::string HandWrittenRecord(const StepRecord& r) {
  std::string b;
  const auto put = [&b](const void* p, size_t n) { b.append(static_cast<const char*>(p), n); };
  put(&r.step, 8);
  put(&r.time_sec, 8);
  const auto field = [&](const auto& v) {
    const uint8_t enc = runlog_codec::kFieldPlain;
    const uint32_t n = static_cast<uint32_t>(v.size());
    put(&enc, 1);
    put(&n, 4);
    put(v.data(), 8 * v.size());
  };
  field(r.qpos);
  field(r.qvel);
  field(r.act);
  field(r.ctrl);
  field(r.qacc_warmstart);
  field(r.qfrc_applied);
  field(r.xfrc_applied);
  field(r.mocap_pos);
  field(r.mocap_quat);
  field(r.userdata);
  field(r.controller_next_update);
  return b;
}

TEST(StateTable, RecordBytesAreTheFieldsOfFormatVersion1InOrder) {
  RunLogLayout layout;
  StateDims dims;
  for (int i = 0; i < kNumStateDims; ++i) dims.n[i] = i + 1;  // every size different
  layout.set_dims(dims);
  EXPECT_EQ(layout.dims(), dims);
  StepRecord r;
  r.step = 7;
  r.time_sec = 0.014;
  double x = 1;
  ForEachStateField(
      [&](const StateFieldInfo& f, auto& v) {
        v.resize(StateFieldSize(f, dims));
        for (auto& e : v) e = static_cast<std::decay_t<decltype(e)>>(x++);
      },
      r);
  std::string body;
  runlog_codec::EncodeStep(r, nullptr, &body);
  EXPECT_EQ(body, HandWrittenRecord(r));
  // and back, checked against the layout
  runlog_codec::BodyReader in(body, "test");
  StepRecord back;
  runlog_codec::DecodeStep(&in, nullptr, &back, &layout);
  EXPECT_TRUE(in.done());
  EXPECT_EQ(back.step, 7);
  EXPECT_EQ(back.qacc_warmstart, r.qacc_warmstart);
  EXPECT_EQ(back.controller_next_update, r.controller_next_update);
  EXPECT_EQ(StateSizeMismatch(back, dims), "");
  EXPECT_EQ(runlog_codec::StepRecordMemoryBytes(layout),
            sizeof(StepRecord) + (body.size() - 16 - 5 * kNumStateFields));
}

TEST(StateTable, DecodeNamesTheFieldThatDisagreesWithTheLayout) {
  RunLogLayout layout;
  layout.nq = 2;
  layout.nv = 1;
  StepRecord r;
  r.qpos = {1, 2};
  r.qvel = {3};
  r.qacc_warmstart = {4, 5};  // nv is 1
  r.qfrc_applied = {0};
  std::string body;
  runlog_codec::EncodeStep(r, nullptr, &body);
  runlog_codec::BodyReader in(body, "steps chunk 1");
  StepRecord back;
  try {
    runlog_codec::DecodeStep(&in, nullptr, &back, &layout);
    FAIL() << "expected a RunLogError";
  } catch (const RunLogError& e) {
    EXPECT_NE(std::string(e.what()).find(
                  "field qacc_warmstart has 2 entries; the header's layout says 1"),
              std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace penumbra
