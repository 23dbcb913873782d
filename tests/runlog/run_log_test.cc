// the run log format (runlog/): every record kind written and read back bit for bit, seeking,
// and each way a log can be refused or damaged: another format version, a truncated header,
// a log cut off mid-chunk (what SIGKILL leaves), a flipped byte, a full disk.

#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <thread>

#include "common/temp_dir.h"
#include "penumbra/runlog/run_log_reader.h"
#include "penumbra/runlog/run_log_writer.h"

namespace penumbra {
namespace {

namespace fs = std::filesystem;

RunLogHeader TestHeader() {
  RunLogHeader h;
  h.penumbra_version = "9.8.7";
  h.mujoco_version = "2.2.2";
  h.world_file = "/w/world.yaml";
  h.world_text = "seed: 3\n# ünïcode and \"quotes\"\n";
  h.composed_mjcf = "<mujoco/>";
  h.assets = {{"world", "/w/world.yaml", std::string(64, 'a'), 17},
              {"mesh", "/w/m.stl", std::string(64, 'b'), 1234567}};
  h.seed = 18446744073709551615ull;
  h.command_line = "penumbra run world.yaml --record x.plog";
  h.timestep_sec = 0.002;
  RunLogLayout& l = h.layout;
  l.nq = 8;
  l.nv = 7;
  l.na = 1;
  l.nu = 2;
  l.nmocap = 1;
  l.nuserdata = 2;
  l.nbody = 3;
  l.num_controllers = 1;
  l.nhistory = 5;
  l.neq = 2;
  l.npluginstate = 1;
  l.nplastic = 3;
  l.joints = {{"ball", "free", 0, 7, 0, 6}, {"arm", "hinge", 7, 1, 6, 1}};
  l.actuator_names = {"a0", "a1"};
  l.mocap_body_names = {"agents/bob"};
  l.body_names = {"world", "ball", "arm"};
  l.controller_names = {"joint_servo"};
  h.has_sensor_records = true;
  h.adversity = "major (presets.yaml)";
  return h;
}

// a state of the test layout at `step` whose numbers change smoothly (and one that is -0.0,
// NaN or huge, to check the bits survive)
StepRecord TestStep(int64_t step) {
  StepRecord r;
  r.step = step;
  r.time_sec = step * 0.002;
  const double t = r.time_sec;
  for (int i = 0; i < 8; ++i) r.qpos.push_back(std::sin(t + i) * (i + 1));
  for (int i = 0; i < 7; ++i) r.qvel.push_back(std::cos(t * 3 + i));
  r.act = {t * 0.5};
  r.ctrl = {std::sin(t), -0.0};
  for (int i = 0; i < 7; ++i) r.qacc_warmstart.push_back(i == 3 ? 1e300 : std::exp(-t * i));
  r.qfrc_applied.assign(7, 0.0);
  r.xfrc_applied.assign(18, 0.0);
  if (step % 5 == 0) r.xfrc_applied[4] = 12.5;
  r.mocap_pos = {t, 2 * t, 0.1};
  r.mocap_quat = {1, 0, 0, 0};
  r.userdata = {std::numeric_limits<double>::quiet_NaN(), static_cast<double>(step)};
  r.controller_next_update = {step / 10 * 10 + 10};
  for (int i = 0; i < 5; ++i) r.history.push_back(std::sin(t - 0.002 * i));
  r.eq_active = {1, step < 50 ? 1.0 : 0.0};
  r.plugin_state = {-t};
  r.plastic = {0, t * t, -0.0};
  return r;
}

// equal bit for bit (NaN == NaN, -0.0 != +0.0)
template <typename T>
bool SameBits(const std::vector<T>& a, const std::vector<T>& b) {
  if (a.size() != b.size()) return false;
  for (size_t i = 0; i < a.size(); ++i)
    if (std::bit_cast<uint64_t>(a[i]) != std::bit_cast<uint64_t>(b[i])) return false;
  return true;
}

void ExpectSameStep(const StepRecord& a, const StepRecord& b) {
  EXPECT_EQ(a.step, b.step);
  EXPECT_EQ(std::bit_cast<uint64_t>(a.time_sec), std::bit_cast<uint64_t>(b.time_sec));
  EXPECT_TRUE(SameBits(a.qpos, b.qpos)) << a.step;
  EXPECT_TRUE(SameBits(a.qvel, b.qvel)) << a.step;
  EXPECT_TRUE(SameBits(a.act, b.act)) << a.step;
  EXPECT_TRUE(SameBits(a.ctrl, b.ctrl)) << a.step;
  EXPECT_TRUE(SameBits(a.qacc_warmstart, b.qacc_warmstart)) << a.step;
  EXPECT_TRUE(SameBits(a.qfrc_applied, b.qfrc_applied)) << a.step;
  EXPECT_TRUE(SameBits(a.xfrc_applied, b.xfrc_applied)) << a.step;
  EXPECT_TRUE(SameBits(a.mocap_pos, b.mocap_pos)) << a.step;
  EXPECT_TRUE(SameBits(a.mocap_quat, b.mocap_quat)) << a.step;
  EXPECT_TRUE(SameBits(a.userdata, b.userdata)) << a.step;
  EXPECT_EQ(a.controller_next_update, b.controller_next_update) << a.step;
  EXPECT_TRUE(SameBits(a.history, b.history)) << a.step;
  EXPECT_TRUE(SameBits(a.eq_active, b.eq_active)) << a.step;
  EXPECT_TRUE(SameBits(a.plugin_state, b.plugin_state)) << a.step;
  EXPECT_TRUE(SameBits(a.plastic, b.plastic)) << a.step;
}

// a closed log of steps 0..n-1 in chunks of `chunk_steps`, with an event every 7 steps
std::string WriteLog(const testing::TempDir& tmp, int n, int chunk_steps,
                     const std::string& name = "run.plog") {
  const std::string path = (tmp.path() / name).string();
  RunLogWriterOptions o;
  o.chunk_steps = chunk_steps;
  RunLogWriter w(path, TestHeader(), o);
  for (int s = 0; s < n; ++s) {
    w.Append(TestStep(s));
    if (s % 7 == 0) w.RecordEvent(s, s * 0.002, "note", "{\"i\":" + std::to_string(s) + "}");
  }
  w.Close();
  return path;
}

std::string ReadBytes(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(f), {});
}
void WriteBytes(const std::string& path, const std::string& bytes) {
  std::ofstream f(path, std::ios::binary | std::ios::trunc);
  f.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

std::string OpenError(const std::string& path, RunLogReadMode mode = RunLogReadMode::kStrict) {
  try {
    RunLogReader::Open(path, mode);
  } catch (const RunLogError& e) {
    return e.what();
  }
  return "";
}

TEST(RunLogTest, RoundTripOfEveryRecordKind) {
  testing::TempDir tmp;
  const std::string path = (tmp.path() / "all.plog").string();
  RunLogWriterOptions o;
  o.chunk_steps = 16;
  std::vector<SensorRecord> sensors;
  {
    RunLogWriter w(path, TestHeader(), o);
    // events from four threads at once while the steps are appended (RecordEvent is
    // thread-safe); sensor records with binary payloads (NUL bytes, all 256 values)
    std::vector<std::thread> threads;
    for (int t = 0; t < 4; ++t)
      threads.emplace_back([&w, t] {
        for (int i = 0; i < 25; ++i)
          w.RecordEvent(i, i * 0.002, "command", "{\"thread\":" + std::to_string(t) + "}");
      });
    for (int s = 0; s < 100; ++s) {
      w.Append(TestStep(s));
      if (s % 10 == 0) {
        SensorRecord r{s, s * 0.002, "front", "rgb.png", std::string()};
        for (int b = 0; b < 256; ++b) r.payload.push_back(static_cast<char>((b + s) & 0xff));
        w.RecordSensor(r);
        sensors.push_back(r);
      }
    }
    for (std::thread& t : threads) t.join();
    w.Close();
    const RunLogWriterStats st = w.stats();
    EXPECT_EQ(st.steps, 100);
    EXPECT_EQ(st.events, 100);
    EXPECT_EQ(st.sensor_records, 10);
    EXPECT_EQ(st.first_step, 0);
    EXPECT_EQ(st.last_step, 99);
    EXPECT_EQ(st.file_bytes, fs::file_size(path));
  }

  RunLogReader r = RunLogReader::Open(path);
  EXPECT_TRUE(r.complete());
  EXPECT_FALSE(r.damage());
  const RunLogHeader& h = r.header();
  const RunLogHeader e = TestHeader();
  EXPECT_EQ(h.format_version, kRunLogFormatVersion);
  EXPECT_EQ(h.penumbra_version, e.penumbra_version);
  EXPECT_EQ(h.world_text, e.world_text);
  EXPECT_EQ(h.composed_mjcf, e.composed_mjcf);
  ASSERT_EQ(h.assets.size(), 2u);
  EXPECT_EQ(h.assets[1].path, "/w/m.stl");
  EXPECT_EQ(h.assets[1].size_bytes, 1234567u);
  EXPECT_EQ(h.seed, e.seed);
  EXPECT_EQ(h.command_line, e.command_line);
  EXPECT_EQ(h.timestep_sec, 0.002);
  EXPECT_EQ(h.layout.nq, 8);
  EXPECT_EQ(h.layout.nbody, 3);
  EXPECT_EQ(h.layout.dims(), e.layout.dims());  // nhistory, neq, npluginstate, nplastic too
  ASSERT_EQ(h.layout.joints.size(), 2u);
  EXPECT_EQ(h.layout.joints[1].name, "arm");
  EXPECT_EQ(h.layout.joints[1].qvel_adr, 6);
  EXPECT_EQ(h.layout.mocap_body_names, e.layout.mocap_body_names);
  EXPECT_EQ(h.layout.controller_names, e.layout.controller_names);
  EXPECT_TRUE(h.has_sensor_records);
  EXPECT_EQ(h.adversity, e.adversity);

  // steps: all of them, in order, bit for bit; 100 steps in chunks of 16 = 7 steps chunks
  EXPECT_EQ(r.num_steps(), 100);
  EXPECT_EQ(r.first_step(), 0);
  EXPECT_EQ(r.last_step(), 99);
  int steps_chunks = 0;
  for (const RunLogChunkInfo& c : r.chunks()) steps_chunks += c.kind == RunLogChunkKind::kSteps;
  EXPECT_EQ(steps_chunks, 7);
  EXPECT_EQ(r.chunks().front().kind, RunLogChunkKind::kHeader);
  EXPECT_EQ(r.chunks().back().kind, RunLogChunkKind::kEnd);
  StepRecord s;
  for (int i = 0; i < 100; ++i) {
    ASSERT_TRUE(r.NextStep(&s)) << i;
    ExpectSameStep(s, TestStep(i));
  }
  EXPECT_FALSE(r.NextStep(&s));

  // random access: into the middle of a chunk, onto a chunk's first step, back to the start
  ASSERT_TRUE(r.SeekStep(37));
  ASSERT_TRUE(r.NextStep(&s));
  ExpectSameStep(s, TestStep(37));
  ASSERT_TRUE(r.NextStep(&s));
  EXPECT_EQ(s.step, 38);
  ASSERT_TRUE(r.SeekStep(48));
  ASSERT_TRUE(r.NextStep(&s));
  ExpectSameStep(s, TestStep(48));
  ASSERT_TRUE(r.SeekStep(-5));
  ASSERT_TRUE(r.NextStep(&s));
  EXPECT_EQ(s.step, 0);
  EXPECT_FALSE(r.SeekStep(100));
  EXPECT_FALSE(r.NextStep(&s));

  // events: every one, by step; each thread's in its order
  const std::vector<EventRecord> events = r.Events();
  ASSERT_EQ(events.size(), 100u);
  for (size_t i = 1; i < events.size(); ++i) EXPECT_LE(events[i - 1].step, events[i].step);
  EXPECT_EQ(events.front().kind, "command");
  EXPECT_EQ(r.Events(10, 12).size(), 12u);  // 4 threads x steps 10, 11, 12

  // sensor records: bytes as given
  const std::vector<SensorRecord> got = r.SensorRecords();
  ASSERT_EQ(got.size(), sensors.size());
  for (size_t i = 0; i < got.size(); ++i) {
    EXPECT_EQ(got[i].step, sensors[i].step);
    EXPECT_EQ(got[i].sensor, "front");
    EXPECT_EQ(got[i].kind, "rgb.png");
    EXPECT_EQ(got[i].payload, sensors[i].payload);
  }

  // every record in file order: 100 steps, 100 events, 10 sensor records
  int n_steps = 0, n_events = 0, n_sensors = 0;
  RunLogRecord rec;
  int64_t last = -1;
  while (r.NextRecord(&rec)) {
    if (const StepRecord* st = std::get_if<StepRecord>(&rec)) {
      EXPECT_GT(st->step, last);
      last = st->step;
      ++n_steps;
    }
    n_events += std::holds_alternative<EventRecord>(rec);
    n_sensors += std::holds_alternative<SensorRecord>(rec);
  }
  EXPECT_EQ(n_steps, 100);
  EXPECT_EQ(n_events, 100);
  EXPECT_EQ(n_sensors, 10);
  r.RewindRecords();
  ASSERT_TRUE(r.NextRecord(&rec));
}

TEST(RunLogTest, AppendRefusesStepsOutOfOrderAndSizesOffTheLayout) {
  testing::TempDir tmp;
  RunLogWriter w((tmp.path() / "x.plog").string(), TestHeader());
  w.Append(TestStep(3));
  try {
    w.Append(TestStep(3));
    FAIL() << "a repeated step was accepted";
  } catch (const RunLogError& e) {
    EXPECT_NE(std::string(e.what()).find("step 3 appended after step 3"), std::string::npos)
        << e.what();
  }
  StepRecord bad = TestStep(4);
  bad.mocap_quat.pop_back();
  try {
    w.Append(bad);
    FAIL() << "a short mocap_quat was accepted";
  } catch (const RunLogError& e) {
    EXPECT_NE(std::string(e.what()).find("mocap_quat has 3 entries; the header's layout says 4"),
              std::string::npos)
        << e.what();
  }
  w.Close();
  EXPECT_THROW(w.Append(TestStep(5)), RunLogError);
}

TEST(RunLogTest, AnotherFormatVersionIsRefusedNamingTheVersionsThatReadIt) {
  testing::TempDir tmp;
  const std::string path = WriteLog(tmp, 10, 4);
  std::string bytes = ReadBytes(path);
  bytes[8] = 3;  // the u32 format version after the 8-byte magic
  WriteBytes(path, bytes);
  const std::string err = OpenError(path, RunLogReadMode::kRecover);
  EXPECT_NE(err.find("run log format version 3 (written by penumbra 9.8.7)"), std::string::npos)
      << err;
  EXPECT_NE(err.find("reads run log format version 1, 2"), std::string::npos) << err;
}

TEST(RunLogTest, ATruncatedHeaderIsAClearErrorInBothModes) {
  testing::TempDir tmp;
  const std::string path = WriteLog(tmp, 10, 4);
  const std::string bytes = ReadBytes(path);
  const std::string cut = (tmp.path() / "cut.plog").string();
  // inside the magic, inside the preamble, inside the header chunk's header, inside its body
  for (size_t n : {size_t{3}, size_t{12}, size_t{16 + 30}, size_t{16 + 64 + 20}}) {
    WriteBytes(cut, bytes.substr(0, n));
    for (RunLogReadMode mode : {RunLogReadMode::kStrict, RunLogReadMode::kRecover}) {
      const std::string err = OpenError(cut, mode);
      EXPECT_NE(err.find("truncated run log header"), std::string::npos) << n << ": " << err;
      EXPECT_NE(err.find(cut), std::string::npos) << err;
    }
  }
  WriteBytes(cut, "");
  EXPECT_NE(OpenError(cut).find("empty file"), std::string::npos);
  WriteBytes(cut, "seed: 3\nduration_sec: 1\n");
  EXPECT_NE(OpenError(cut).find("not a penumbra run log"), std::string::npos);
}

// the offset of the header of chunk `index` (scanning the chunk headers)
uint64_t ChunkOffset(const std::string& path, uint64_t index) {
  RunLogReader r = RunLogReader::Open(path);
  return r.chunks().at(index).file_offset;
}

TEST(RunLogTest, ALogCutMidChunkReadsToItsLastCompleteChunkAndNamesIt) {
  testing::TempDir tmp;
  // 100 steps in chunks of 10 (chunk 1 = steps 0..9, then an events chunk, ...)
  const std::string path = WriteLog(tmp, 100, 10);
  const RunLogReader full = RunLogReader::Open(path);
  // the steps chunk holding steps 50..59, and the chunk before it
  size_t pos = 0;
  for (size_t i = 0; i < full.chunks().size(); ++i)
    if (full.chunks()[i].kind == RunLogChunkKind::kSteps && full.chunks()[i].first_step == 50)
      pos = i;
  ASSERT_GT(pos, 1u);
  const RunLogChunkInfo cut_chunk = full.chunks()[pos];
  const std::string bytes = ReadBytes(path);
  WriteBytes(path, bytes.substr(0, cut_chunk.file_offset + 64 + cut_chunk.compressed_size / 2));

  const std::string err = OpenError(path);
  EXPECT_NE(err.find("log ends at chunk " + std::to_string(pos - 1) + " (step 49): chunk " +
                     std::to_string(pos) + " (steps, steps 50..59) is cut off"),
            std::string::npos)
      << err;

  RunLogReader r = RunLogReader::Open(path, RunLogReadMode::kRecover);
  EXPECT_FALSE(r.complete());
  ASSERT_TRUE(r.damage());
  EXPECT_NE(r.damage()->find("log ends at chunk " + std::to_string(pos - 1) + " (step 49)"),
            std::string::npos)
      << *r.damage();
  EXPECT_EQ(r.last_step(), 49);
  StepRecord s;
  int n = 0;
  while (r.NextStep(&s)) ExpectSameStep(s, TestStep(n++));
  EXPECT_EQ(n, 50);

  // cut exactly at a chunk boundary: whole chunks, but no end chunk
  WriteBytes(path, bytes.substr(0, cut_chunk.file_offset));
  const std::string err2 = OpenError(path);
  EXPECT_NE(err2.find("(step 49): the log has no end chunk"), std::string::npos) << err2;
}

TEST(RunLogTest, AFlippedByteIsReportedWithItsChunkIndex) {
  testing::TempDir tmp;
  const std::string path = WriteLog(tmp, 100, 10);
  const std::string bytes = ReadBytes(path);
  const uint64_t chunk3 = ChunkOffset(path, 3);
  {
    // in chunk 3's body: strict mode refuses naming chunk 3, recovery reads chunks 0..2
    std::string b = bytes;
    b[chunk3 + 64 + 5] ^= 0x10;
    WriteBytes(path, b);
    const std::string err = OpenError(path);
    EXPECT_NE(err.find("CRC mismatch in chunk 3"), std::string::npos) << err;
    EXPECT_NE(err.find("log ends at chunk 2"), std::string::npos) << err;
    RunLogReader r = RunLogReader::Open(path, RunLogReadMode::kRecover);
    EXPECT_EQ(r.chunks().size(), 3u);
    ASSERT_TRUE(r.damage());
    EXPECT_NE(r.damage()->find("CRC mismatch in chunk 3"), std::string::npos);
  }
  {
    // in chunk 3's header (its record count)
    std::string b = bytes;
    b[chunk3 + 16] ^= 0x01;
    WriteBytes(path, b);
    const std::string err = OpenError(path);
    EXPECT_NE(err.find("chunk 3 (at byte " + std::to_string(chunk3) +
                       ") is damaged: chunk header CRC mismatch"),
              std::string::npos)
        << err;
  }
}

TEST(RunLogTest, WriteErrorsAreReportedNotSwallowed) {
  // /dev/full: every write fails with ENOSPC (a full disk)
  if (!fs::exists("/dev/full")) GTEST_SKIP() << "no /dev/full";
  try {
    RunLogWriter w("/dev/full", TestHeader());
    FAIL() << "writing to a full disk succeeded";
  } catch (const RunLogError& e) {
    EXPECT_NE(std::string(e.what()).find("No space left on device"), std::string::npos) << e.what();
  }
  testing::TempDir tmp;
  EXPECT_THROW(RunLogWriter((tmp.path() / "no" / "such" / "x.plog").string(), TestHeader()),
               RunLogError);
}

TEST(RunLogTest, Sha256OfKnownText) {
  // FIPS 180-2 test vector
  EXPECT_EQ(Sha256Hex("abc"), "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
  testing::TempDir tmp;
  uint64_t size = 0;
  EXPECT_EQ(Sha256OfFile(tmp.Write("a.txt", "abc"), &size), Sha256Hex("abc"));
  EXPECT_EQ(size, 3u);
}

}  // namespace
}  // namespace penumbra
