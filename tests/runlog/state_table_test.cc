// the state table (scene/sim_state.h kStateFields) is the run log's step record: docs/run-log.md
// lists the fields in table order with their sizes, and a record's bytes are the fields in that
// order (a log written before the table existed, with its hand-written field list, reads the
// same), so a change of the table that would break old logs fails here. a format 1 log (MuJoCo
// 2.2.2's state, before history, eq_active, plugin_state and plastic) reads with those fields
// empty and their dimensions 0.
#include <gtest/gtest.h>

#include <bit>
#include <cstring>
#include <filesystem>
#include <regex>
#include <string>
#include <type_traits>
#include <vector>

#include "common/temp_dir.h"
#include "penumbra/runlog/run_log_codec.h"
#include "penumbra/runlog/run_log_reader.h"

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
// the order of format version `version` (independent of the table): step, time, then per field
// an encoding byte, a u32 count and the words
std::string HandWrittenRecord(const StepRecord& r, uint32_t version) {
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
  if (version == 1) return b;
  field(r.history);
  field(r.eq_active);
  field(r.plugin_state);
  field(r.plastic);
  return b;
}

// a record of `layout` whose entries are all different (x, x + 1, ...; flags 0 / 1)
StepRecord NumberedRecord(const StateDims& dims, int64_t step, double x) {
  StepRecord r;
  r.step = step;
  r.time_sec = 0.002 * static_cast<double>(step);
  ForEachStateField(
      [&](const StateFieldInfo& f, auto& v) {
        v.resize(StateFieldSize(f, dims));
        for (auto& e : v) e = static_cast<std::decay_t<decltype(e)>>(f.flag ? 1 : x++);
      },
      r);
  return r;
}

TEST(StateTable, RecordBytesAreTheFieldsOfTheFormatVersionInOrder) {
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
  EXPECT_EQ(kRunLogFormatVersion, 2u);
  EXPECT_EQ(body, HandWrittenRecord(r, 2));
  // and back, checked against the layout
  runlog_codec::BodyReader in(body, "test");
  StepRecord back;
  runlog_codec::DecodeStep(&in, nullptr, &back, &layout);
  EXPECT_TRUE(in.done());
  EXPECT_EQ(back.step, 7);
  EXPECT_EQ(back.qacc_warmstart, r.qacc_warmstart);
  EXPECT_EQ(back.controller_next_update, r.controller_next_update);
  EXPECT_EQ(back.history, r.history);
  EXPECT_EQ(back.eq_active, r.eq_active);
  EXPECT_EQ(back.plugin_state, r.plugin_state);
  EXPECT_EQ(back.plastic, r.plastic);
  EXPECT_EQ(StateDimsOf(back), dims);
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

// a format 1 record: the 11 fields of MuJoCo 2.2.2's state, no more; the fields format 2 added
// are left empty, and a record of format 2 read as format 1 leaves bytes over
TEST(StateTable, AFormat1RecordDecodesWithTheLaterFieldsEmpty) {
  StateDims dims;
  for (int i = 0; i < RunLogStateShapeOf(1).dims; ++i) dims.n[i] = i + 1;
  RunLogLayout layout;
  layout.set_dims(dims);
  const StepRecord r = NumberedRecord(dims, 3, 1);
  const std::string v1 = HandWrittenRecord(r, 1);
  size_t entries = 0;
  for (int i = 0; i < 11; ++i) entries += StateFieldSize(kStateFields[i], dims);
  EXPECT_EQ(v1.size(), 16 + 5 * 11 + 8 * entries);
  runlog_codec::BodyReader in(v1, "test");
  StepRecord back;
  back.history = {9};  // a decode leaves no stale entries
  runlog_codec::DecodeStep(&in, nullptr, &back, &layout, 1);
  EXPECT_TRUE(in.done());
  EXPECT_EQ(back.qpos, r.qpos);
  EXPECT_EQ(back.userdata, r.userdata);
  EXPECT_EQ(back.controller_next_update, r.controller_next_update);
  EXPECT_TRUE(back.history.empty());
  EXPECT_TRUE(back.eq_active.empty());
  EXPECT_TRUE(back.plugin_state.empty());
  EXPECT_TRUE(back.plastic.empty());
  EXPECT_EQ(runlog_codec::MinStepRecordBytes(1), 71u);
  EXPECT_EQ(runlog_codec::MinStepRecordBytes(2), 91u);
}

// a chunk as docs/run-log.md "Chunk" spells it: header, body stored as is, body CRC
std::string Chunk(RunLogChunkKind kind, uint64_t index, uint32_t records, int64_t first,
                  int64_t last, const std::string& body) {
  runlog_codec::ChunkHeader h;
  h.kind = kind;
  h.index = index;
  h.record_count = records;
  h.codec = runlog_codec::kCodecNone;
  h.first_step = first;
  h.last_step = last;
  h.raw_size = h.stored_size = body.size();
  std::string out = runlog_codec::EncodeChunkHeader(h) + body;
  runlog_codec::PutU32(&out, runlog_codec::Crc32(body.data(), body.size()));
  return out;
}

// a whole format 1 log, as a penumbra of format 1 wrote it: preamble version 1, a header whose
// layout has no nhistory, neq, npluginstate or nplastic, records of 11 fields (the first of a
// chunk plain, the others XORed with it)
TEST(StateTable, AFormat1LogReadsWithItsStepsUnchanged) {
  testing::TempDir tmp;
  RunLogHeader h;
  h.format_version = 1;
  h.penumbra_version = "0.1.0";
  h.mujoco_version = "2.2.2";
  h.composed_mjcf = "<mujoco/>";
  h.timestep_sec = 0.002;
  RunLogLayout& l = h.layout;
  l.nq = 2;
  l.nv = 2;
  l.nu = 1;
  l.nbody = 2;
  l.num_controllers = 1;
  l.joints = {{"a", "hinge", 0, 1, 0, 1}, {"b", "slide", 1, 1, 1, 1}};
  l.actuator_names = {"m"};
  l.body_names = {"world", "b"};
  l.controller_names = {"joint_pd"};
  const std::string json = runlog_codec::HeaderToJson(h);
  EXPECT_EQ(json.find("nhistory"), std::string::npos);
  EXPECT_EQ(json.find("\"neq\""), std::string::npos);
  EXPECT_NE(json.find("\"num_controllers\""), std::string::npos);

  std::vector<StepRecord> steps;
  for (int64_t s = 0; s < 5; ++s) steps.push_back(NumberedRecord(l.dims(), s, 10.0 * s + 0.5));
  std::string body;
  for (size_t i = 0; i < steps.size(); ++i) {
    if (i == 0) {
      body += HandWrittenRecord(steps[0], 1);
      continue;
    }
    // XOR against the previous record of the chunk, field by field (encoding 1)
    StepRecord x = steps[i];
    ForEachStateField(
        [&](const StateFieldInfo&, auto& v, const auto& prev) {
          for (size_t k = 0; k < v.size(); ++k)
            v[k] = std::bit_cast<std::decay_t<decltype(v[k])>>(std::bit_cast<uint64_t>(v[k]) ^
                                                               std::bit_cast<uint64_t>(prev[k]));
        },
        x, steps[i - 1]);
    std::string rec = HandWrittenRecord(x, 1);
    // the encoding byte of each of the 11 fields: plain -> xor
    size_t at = 16;
    ForEachStateField(
        [&](const StateFieldInfo& f, const auto& v) {
          if (static_cast<int>(f.field) >= 11) return;
          rec[at] = static_cast<char>(runlog_codec::kFieldXor);
          at += 5 + 8 * v.size();
        },
        x);
    body += rec;
  }
  const std::string end =
      R"({"steps":5,"events":0,"sensor_records":0,"first_step":0,"last_step":4})";
  const std::string bytes = runlog_codec::EncodePreamble(1) +
                            Chunk(RunLogChunkKind::kHeader, 0, 1, 0, 0, json) +
                            Chunk(RunLogChunkKind::kSteps, 1, 5, 0, 4, body) +
                            Chunk(RunLogChunkKind::kEnd, 2, 1, 0, 4, end);
  const std::string path = tmp.Write("v1.plog", bytes);

  RunLogReader log = RunLogReader::Open(path);
  EXPECT_TRUE(log.complete());
  EXPECT_EQ(log.header().format_version, 1u);
  const StateDims dims = log.header().layout.dims();
  EXPECT_EQ(dims, l.dims());
  EXPECT_EQ(dims[StateDim::kNhistory], 0);
  EXPECT_EQ(dims[StateDim::kNeq], 0);
  EXPECT_EQ(dims[StateDim::kNpluginstate], 0);
  EXPECT_EQ(dims[StateDim::kNplastic], 0);
  StepRecord r;
  size_t n = 0;
  while (log.NextStep(&r)) {
    ASSERT_LT(n, steps.size());
    const StepRecord& want = steps[n++];
    EXPECT_EQ(r.step, want.step);
    EXPECT_EQ(r.time_sec, want.time_sec);
    bool same = true;
    ForEachStateField([&](const StateFieldInfo&, const auto& a, const auto& b) { same &= a == b; },
                      r, want);
    EXPECT_TRUE(same) << "step " << r.step;
    EXPECT_EQ(StateMismatch(r, dims), "");
  }
  EXPECT_EQ(n, steps.size());
}

}  // namespace
}  // namespace penumbra
