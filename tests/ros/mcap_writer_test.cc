// the MCAP writer (ros/mcap_writer.h), read back by the official `mcap` Python reader
// (tests/ros/mcap_read_check.py in the project venv, .venv: scripts/install-deps.sh): records,
// statistics, summary, indexes and CRCs as the spec (https://mcap.dev/spec) defines them.
#include "penumbra/ros/mcap_writer.h"

#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <spawn.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "common/temp_dir.h"
#include "penumbra/core/error.h"

extern char** environ;

namespace penumbra {
namespace {

namespace fs = std::filesystem;

// the project venv's python, "" when there is none
std::string VenvPython() {
  const std::string p = PENUMBRA_SOURCE_DIR "/.venv/bin/python";
  return fs::exists(p) ? p : "";
}

// runs tests/ros/mcap_read_check.py on `file` (no shell) and parses what it printed
nlohmann::json ReadBack(const std::string& python, const fs::path& file, const fs::path& dir) {
  const fs::path out = dir / "read.json", err = dir / "read.err";
  std::vector<std::string> args = {python, PENUMBRA_SOURCE_DIR "/tests/ros/mcap_read_check.py",
                                   file.string()};
  std::vector<char*> argv;
  for (std::string& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  posix_spawn_file_actions_t fa;
  posix_spawn_file_actions_init(&fa);
  posix_spawn_file_actions_addopen(&fa, 1, out.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_addopen(&fa, 2, err.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  pid_t pid = 0;
  const int rc = posix_spawn(&pid, argv[0], &fa, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&fa);
  if (rc != 0) throw std::runtime_error("posix_spawn " + python + " failed");
  int status = 0;
  waitpid(pid, &status, 0);
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0)
    throw std::runtime_error("mcap_read_check.py failed:\n" + testing::ReadAll(err));
  return nlohmann::json::parse(testing::ReadAll(out));
}

std::string Hex(const std::vector<uint8_t>& b) {
  static const char* d = "0123456789abcdef";
  std::string s;
  for (uint8_t c : b) {
    s.push_back(d[c >> 4]);
    s.push_back(d[c & 15]);
  }
  return s;
}

struct Sent {
  uint16_t channel;
  uint32_t sequence;
  uint64_t log_time, publish_time;
  std::vector<uint8_t> data;
};

class McapWriterRoundTrip : public ::testing::TestWithParam<McapCompression> {};

TEST_P(McapWriterRoundTrip, TheOfficialReaderReadsBackEverything) {
  const std::string python = VenvPython();
  if (python.empty()) GTEST_SKIP() << "no project venv (.venv: scripts/install-deps.sh)";
  testing::TempDir dir;
  const fs::path file = dir.path() / "t.mcap";
  McapWriterOptions options;
  options.profile = "ros2";
  options.compression = GetParam();
  options.chunk_bytes = 700;  // several chunks
  std::vector<Sent> sent;
  {
    McapWriter w(file.string(), options);
    const uint16_t s1 = w.AddSchema("sensor_msgs/msg/Imu", "ros2msg", "float64 x\nfloat64 y\n");
    const uint16_t s2 = w.AddSchema("std_msgs/msg/String", "ros2msg", "string data\n");
    EXPECT_EQ(s1, 1);
    EXPECT_EQ(s2, 2);
    const uint16_t imu =
        w.AddChannel(s1, "/imu", "cdr", {{"offered_qos_profiles", "- depth: 5\n"}});
    const uint16_t text = w.AddChannel(s2, "/text", "cdr", {});
    EXPECT_EQ(imu, 1);
    EXPECT_EQ(text, 2);
    w.AddMetadata("rosbag2", {{"serialized_metadata", "version: 9"}, {"ROS_DISTRO", "jazzy"}});
    uint32_t seq[3] = {0, 0, 0};
    for (int i = 0; i < 40; ++i) {
      // out of time order within and across chunks; one empty payload; one larger than a chunk
      const uint16_t ch = i % 3 == 0 ? text : imu;
      const uint64_t t = static_cast<uint64_t>((i * 7919) % 40) * 1000000 + 5;
      std::vector<uint8_t> data(i == 7 ? 0 : (i == 11 ? 3000 : 16 + i), 0);
      for (size_t k = 0; k < data.size(); ++k) data[k] = static_cast<uint8_t>(k * 31 + i);
      w.WriteMessage(ch, t, t + 1, data);
      sent.push_back({ch, ++seq[ch], t, t + 1, data});
    }
    // a channel added after messages were written, with no schema
    const uint16_t late = w.AddChannel(0, "/late", "json", {{"a", "1"}, {"b", ""}});
    w.WriteMessage(late, 2, 2, std::vector<uint8_t>{'{', '}'});
    sent.push_back({late, 1, 2, 2, {'{', '}'}});
    EXPECT_EQ(w.messages(), 41u);
    EXPECT_EQ(w.messages(text), 14u);
    EXPECT_EQ(w.message_start_time(), 2u);
    EXPECT_EQ(w.message_end_time(), 39000005u);
    w.Close();
  }
  const nlohmann::json r = ReadBack(python, file, dir.path());
  EXPECT_EQ(r["profile"], "ros2");
  EXPECT_EQ(r["library"], "penumbra");
  const nlohmann::json& st = r["statistics"];
  EXPECT_EQ(st["message_count"], 41);
  EXPECT_EQ(st["schema_count"], 2);
  EXPECT_EQ(st["channel_count"], 3);
  EXPECT_EQ(st["metadata_count"], 1);
  EXPECT_EQ(st["message_start_time"], 2);
  EXPECT_EQ(st["message_end_time"], 39000005);
  EXPECT_EQ(st["channel_message_counts"], (nlohmann::json{{"1", 26}, {"2", 14}, {"3", 1}}));
  EXPECT_GT(st["chunk_count"].get<int>(), 3);
  EXPECT_EQ(r["chunk_indexes"].size(), st["chunk_count"].get<size_t>());
  for (const nlohmann::json& c : r["chunk_indexes"])
    EXPECT_EQ(c["compression"], GetParam() == McapCompression::kZstd ? "zstd" : "");
  EXPECT_EQ(r["schemas"]["1"]["name"], "sensor_msgs/msg/Imu");
  EXPECT_EQ(r["schemas"]["1"]["encoding"], "ros2msg");
  EXPECT_EQ(r["schemas"]["1"]["data"], "float64 x\nfloat64 y\n");
  EXPECT_EQ(r["schemas"]["2"]["data"], "string data\n");
  EXPECT_EQ(r["channels"]["1"]["topic"], "/imu");
  EXPECT_EQ(r["channels"]["1"]["schema_id"], 1);
  EXPECT_EQ(r["channels"]["1"]["message_encoding"], "cdr");
  EXPECT_EQ(r["channels"]["1"]["metadata"],
            (nlohmann::json{{"offered_qos_profiles", "- depth: 5\n"}}));
  EXPECT_EQ(r["channels"]["2"]["metadata"], nlohmann::json::object());
  EXPECT_EQ(r["channels"]["3"]["schema_id"], 0);
  EXPECT_EQ(r["channels"]["3"]["metadata"], (nlohmann::json{{"a", "1"}, {"b", ""}}));
  EXPECT_EQ(r["metadata"]["rosbag2"],
            (nlohmann::json{{"serialized_metadata", "version: 9"}, {"ROS_DISTRO", "jazzy"}}));
  EXPECT_EQ(r["summary_crc_ok"], true);
  EXPECT_EQ(r["data_section_crc_set"], true);
  EXPECT_EQ(r["message_indexes_ok"], true);
  EXPECT_EQ(r["footer_length"], 20);
  // file order: header, the data section (schemas, channels, metadata, chunks each followed by
  // message indexes), DataEnd, then the summary and footer
  const std::vector<std::string> order = r["record_order"];
  ASSERT_GE(order.size(), 6u);
  EXPECT_EQ(order.front(), "Header");
  EXPECT_EQ(order.back(), "Footer");
  const auto data_end = std::find(order.begin(), order.end(), "DataEnd");
  ASSERT_NE(data_end, order.end());
  EXPECT_EQ(std::find(data_end, order.end(), "Chunk"), order.end());
  EXPECT_NE(std::find(data_end, order.end(), "Statistics"), order.end());
  EXPECT_NE(std::find(data_end, order.end(), "ChunkIndex"), order.end());
  EXPECT_NE(std::find(data_end, order.end(), "SummaryOffset"), order.end());
  // every message, in log-time order (stable for equal times: the order written)
  std::stable_sort(sent.begin(), sent.end(),
                   [](const Sent& a, const Sent& b) { return a.log_time < b.log_time; });
  const nlohmann::json& msgs = r["messages"];
  ASSERT_EQ(msgs.size(), sent.size());
  for (size_t i = 0; i < sent.size(); ++i) {
    EXPECT_EQ(msgs[i]["channel"], sent[i].channel) << i;
    EXPECT_EQ(msgs[i]["sequence"], sent[i].sequence) << i;
    EXPECT_EQ(msgs[i]["log_time"], sent[i].log_time) << i;
    EXPECT_EQ(msgs[i]["publish_time"], sent[i].publish_time) << i;
    EXPECT_EQ(msgs[i]["data"], Hex(sent[i].data)) << i;
  }
}

INSTANTIATE_TEST_SUITE_P(Compression, McapWriterRoundTrip,
                         ::testing::Values(McapCompression::kNone, McapCompression::kZstd),
                         [](const auto& info) {
                           return info.param == McapCompression::kZstd ? "Zstd" : "None";
                         });

TEST(McapWriter, AFileWithNoMessagesIsValid) {
  const std::string python = VenvPython();
  if (python.empty()) GTEST_SKIP() << "no project venv (.venv: scripts/install-deps.sh)";
  testing::TempDir dir;
  const fs::path file = dir.path() / "empty.mcap";
  {
    McapWriter w(file.string(), {});
    w.AddChannel(0, "/nothing", "cdr", {});
  }  // closed by the destructor
  const nlohmann::json r = ReadBack(python, file, dir.path());
  EXPECT_EQ(r["statistics"]["message_count"], 0);
  EXPECT_EQ(r["statistics"]["chunk_count"], 0);
  EXPECT_EQ(r["channels"]["1"]["topic"], "/nothing");
  EXPECT_EQ(r["messages"].size(), 0u);
  EXPECT_EQ(r["summary_crc_ok"], true);
}

TEST(McapWriter, AnExistingFileIsNeverReplaced) {
  testing::TempDir dir;
  const std::string path = dir.Write("x.mcap", "keep");
  try {
    McapWriter w(path, {}, "shown.mcap");
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("shown.mcap"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("File exists"), std::string::npos) << e.what();
  }
  EXPECT_EQ(testing::ReadAll(path), "keep");
}

TEST(McapWriter, BadIdsAndSizesAreRefused) {
  testing::TempDir dir;
  McapWriter w((dir.path() / "b.mcap").string(), {});
  EXPECT_THROW(w.AddChannel(1, "/t", "cdr", {}), Error);  // no schema 1
  const uint16_t ch = w.AddChannel(0, "/t", "cdr", {});
  const std::vector<uint8_t> small(4);
  EXPECT_THROW(w.WriteMessage(0, 1, 1, small), Error);
  EXPECT_THROW(w.WriteMessage(ch + 1, 1, 1, small), Error);
  // the size is checked before a byte is read
  EXPECT_THROW(
      w.WriteMessage(ch, 1, 1, std::span<const uint8_t>(small.data(), kMcapMaxMessageBytes + 1)),
      Error);
  EXPECT_THROW(w.AddSchema(std::string(kMcapMaxNameBytes + 1, 'n'), "ros2msg", ""), Error);
  EXPECT_THROW(w.AddSchema("n", "ros2msg", std::string(kMcapMaxSchemaBytes + 1, 'd')), Error);
  EXPECT_THROW(McapWriter((dir.path() / "c.mcap").string(), {.chunk_bytes = 0}), Error);
  w.WriteMessage(ch, 1, 1, small);
  w.Close();
  EXPECT_THROW(w.WriteMessage(ch, 1, 1, small), Error);  // closed
}

// a write past the file size limit (RLIMIT_FSIZE, with SIGXFSZ ignored: EFBIG) stands in for a
// full disk: the error names the file and the system's reason, and the writer is abandoned
TEST(McapWriterWriteFailure, ThrowsTheSystemsReasonAndAbandonsTheFile) {
  testing::TempDir dir;
  const fs::path file = dir.path() / "big.mcap";
  struct rlimit old {};
  ASSERT_EQ(getrlimit(RLIMIT_FSIZE, &old), 0);
  struct sigaction ignore {
  }, old_action{};
  ignore.sa_handler = SIG_IGN;
  ASSERT_EQ(sigaction(SIGXFSZ, &ignore, &old_action), 0);
  struct Restore {
    rlimit limit;
    struct sigaction action;
    ~Restore() {
      setrlimit(RLIMIT_FSIZE, &limit);
      sigaction(SIGXFSZ, &action, nullptr);
    }
  } restore{old, old_action};
  struct rlimit small = old;
  small.rlim_cur = 64 << 10;
  ASSERT_EQ(setrlimit(RLIMIT_FSIZE, &small), 0);
  std::string message;
  {
    McapWriter w(file.string(), {.compression = McapCompression::kNone, .chunk_bytes = 4096},
                 "shown.mcap");
    const uint16_t ch = w.AddChannel(0, "/img", "cdr", {});
    const std::vector<uint8_t> data(10000, 7);
    try {
      for (int i = 0; i < 1000; ++i) w.WriteMessage(ch, i, i, data);
      w.Close();
    } catch (const Error& e) {
      message = e.what();
    }
    EXPECT_THROW(w.WriteMessage(ch, 1, 1, data), Error);
    EXPECT_NO_THROW(w.Close());  // abandoned: nothing more is written
  }
  EXPECT_NE(message.find("shown.mcap"), std::string::npos) << message;
  EXPECT_NE(message.find("File too large"), std::string::npos) << message;
  EXPECT_LE(fs::file_size(file), 64u << 10);
}

}  // namespace
}  // namespace penumbra
