// the one policy for files a client names (core/output_path_policy.h): a new file inside the
// output folder, never outside it, never through a link, never over an existing file. each
// refusal names the path and the rule, and leaves the disk as it was.

#include "penumbra/core/output_path_policy.h"

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "common/temp_dir.h"

namespace penumbra {
namespace {

namespace fs = std::filesystem;

// every entry under `dir` (links not followed), relative, sorted
std::vector<std::string> PolicyTreeOf(const fs::path& dir) {
  std::vector<std::string> out;
  for (auto it = fs::recursive_directory_iterator(dir); it != fs::recursive_directory_iterator();
       ++it)
    out.push_back(it->path().lexically_relative(dir).string());
  std::sort(out.begin(), out.end());
  return out;
}

// the message of the OutputPathError OpenNewFileInside throws ("" if none)
std::string PolicyRefusal(const fs::path& root, const std::string& client_path) {
  try {
    OpenNewFileInside(root, client_path, ".plog");
  } catch (const OutputPathError& e) {
    EXPECT_EQ(e.client_path(), client_path);
    return e.what();
  }
  return "";
}

class OutputPathPolicyTest : public ::testing::Test {
 protected:
  void SetUp() override {
    root_ = tmp_.path() / "out";
    outside_ = tmp_.path() / "outside";
    fs::create_directories(root_ / "logs");
    fs::create_directories(outside_);
  }
  penumbra::testing::TempDir tmp_;
  fs::path root_, outside_;
};

TEST_F(OutputPathPolicyTest, CreatesANewFileInsideTheFolder) {
  NewOutputFile f = OpenNewFileInside(root_, "live.plog", ".plog");
  ASSERT_GE(f.fd.get(), 0);
  EXPECT_EQ(f.relative, "live.plog");
  EXPECT_EQ(f.path, root_ / "live.plog");
  ASSERT_EQ(::write(f.fd.get(), "abc", 3), 3);
  EXPECT_EQ(testing::ReadAll(root_ / "live.plog"), "abc");
  NewOutputFile g = OpenNewFileInside(root_, "logs/second.plog", ".plog");
  EXPECT_EQ(g.path, root_ / "logs" / "second.plog");
  EXPECT_TRUE(fs::is_regular_file(root_ / "logs" / "second.plog"));
}

TEST_F(OutputPathPolicyTest, RefusesPathsOutsideTheFolderNamingPathAndRule) {
  const std::string abs = (outside_ / "x.plog").string();
  std::string m = PolicyRefusal(root_, abs);
  EXPECT_NE(m.find("output path '" + abs + "'"), std::string::npos) << m;
  EXPECT_NE(m.find("is absolute"), std::string::npos) << m;
  m = PolicyRefusal(root_, "../outside/x.plog");
  EXPECT_NE(m.find("'../outside/x.plog'"), std::string::npos) << m;
  EXPECT_NE(m.find("'..' component"), std::string::npos) << m;
  m = PolicyRefusal(root_, "logs/../../outside/x.plog");
  EXPECT_NE(m.find("'..' component"), std::string::npos) << m;
  EXPECT_NE(PolicyRefusal(root_, "").find("is empty"), std::string::npos);
  EXPECT_NE(PolicyRefusal(root_, "logs//a.plog").find("empty component"), std::string::npos);
  EXPECT_NE(PolicyRefusal(root_, "logs/").find("empty component"), std::string::npos);
  EXPECT_NE(PolicyRefusal(root_, "./a.plog").find("'.' component"), std::string::npos);
  m = PolicyRefusal(root_, std::string("a\nb.plog"));
  EXPECT_NE(m.find("control character \\x0a"), std::string::npos) << m;
  EXPECT_EQ(m.find('\n'), std::string::npos) << "the message is one line";
  EXPECT_NE(PolicyRefusal(root_, "a.txt").find("does not end in .plog"), std::string::npos);
  EXPECT_NE(PolicyRefusal(root_, "a.plog.sh").find("does not end in .plog"), std::string::npos);
  EXPECT_NE(PolicyRefusal(root_, ".plog").find("no name before .plog"), std::string::npos);
  EXPECT_NE(PolicyRefusal(root_, std::string(2000, 'a') + ".plog").find("bytes long"),
            std::string::npos);
  m = PolicyRefusal(root_, "missing/a.plog");
  EXPECT_NE(m.find("'missing' does not exist"), std::string::npos) << m;
  // nothing was created anywhere
  EXPECT_EQ(PolicyTreeOf(tmp_.path()), (std::vector<std::string>{"out", "out/logs", "outside"}));
}

TEST_F(OutputPathPolicyTest, NeverFollowsALinkBelowTheFolder) {
  fs::create_directory_symlink(outside_, root_ / "escape");
  std::string m = PolicyRefusal(root_, "escape/x.plog");
  EXPECT_NE(m.find("'escape' is a symbolic link"), std::string::npos) << m;
  fs::create_directory_symlink(outside_, root_ / "logs" / "deeper");
  m = PolicyRefusal(root_, "logs/deeper/x.plog");
  EXPECT_NE(m.find("'logs/deeper' is a symbolic link"), std::string::npos) << m;
  // a dangling link as the file itself: not followed, not created through
  fs::create_symlink(outside_ / "target.plog", root_ / "dangling.plog");
  m = PolicyRefusal(root_, "dangling.plog");
  EXPECT_NE(m.find("already exists (a symbolic link)"), std::string::npos) << m;
  // a file where a folder is expected
  tmp_.Write("out/plain", "x");
  m = PolicyRefusal(root_, "plain/x.plog");
  EXPECT_NE(m.find("'plain' is a file, not a folder"), std::string::npos) << m;
  EXPECT_TRUE(fs::is_empty(outside_));
  EXPECT_FALSE(fs::exists(outside_ / "target.plog"));
}

TEST_F(OutputPathPolicyTest, NeverOverwritesAnExistingFile) {
  tmp_.Write("out/old.plog", "keep me");
  const std::string m = PolicyRefusal(root_, "old.plog");
  EXPECT_NE(m.find("'old.plog': already exists (a file)"), std::string::npos) << m;
  EXPECT_NE(m.find("never overwritten"), std::string::npos) << m;
  EXPECT_EQ(testing::ReadAll(root_ / "old.plog"), "keep me");
}

TEST_F(OutputPathPolicyTest, TheFolderItselfMayBeALinkTheUserMade) {
  fs::create_directory_symlink(root_, tmp_.path() / "out_link");
  NewOutputFile f = OpenNewFileInside(tmp_.path() / "out_link", "a.plog", ".plog");
  EXPECT_TRUE(fs::is_regular_file(root_ / "a.plog"));
  EXPECT_NE(PolicyRefusal(tmp_.path() / "absent", "a.plog").find("cannot be opened"),
            std::string::npos);
}

// the read side (ReadExistingFileInside: set_adversity's preset files): an existing regular
// file inside the folder, never outside it, never through a link, never more than the cap;
// a refusal names the path and the rule and never quotes the file
std::string ReadRefusal(const fs::path& root, const std::string& client_path,
                        size_t max_bytes = 1 << 20) {
  try {
    ReadExistingFileInside(root, client_path, ".yaml", max_bytes, "the world file's folder");
  } catch (const InputPathError& e) {
    EXPECT_EQ(e.client_path(), client_path);
    return e.what();
  }
  return "";
}

TEST_F(OutputPathPolicyTest, ReadsAnExistingFileInsideTheFolder) {
  tmp_.Write("out/presets/fog.yaml", "presets: {}\n");
  const ExistingInputFile f =
      ReadExistingFileInside(root_, "presets/fog.yaml", ".yaml", 100, "the folder");
  EXPECT_EQ(f.text, "presets: {}\n");
  EXPECT_EQ(f.relative, "presets/fog.yaml");
  EXPECT_EQ(f.path, root_ / "presets/fog.yaml");
}

TEST_F(OutputPathPolicyTest, ReadRefusesPathsOutsideTheFolderAndQuotesNoContent) {
  const std::string secret = tmp_.Write("outside/secret.yaml", "token: SECRET-CONTENT\n");
  const std::vector<std::pair<std::string, std::string>> cases = {
      {secret, "is absolute"},
      {"../outside/secret.yaml", "'..' component"},
      {"logs/../../outside/secret.yaml", "'..' component"},
      {"./a.yaml", "'.' component"},
      {"a.yml", "does not end in .yaml"},
      {"missing.yaml", "does not exist"},
      {"nofolder/a.yaml", "the folder 'nofolder' does not exist"},
  };
  for (const auto& [path, rule] : cases) {
    const std::string m = ReadRefusal(root_, path);
    EXPECT_NE(m.find(rule), std::string::npos) << path << ": " << m;
    EXPECT_EQ(m.find("SECRET"), std::string::npos) << m;
    EXPECT_EQ(m.find(root_.string() + "/"), std::string::npos) << m;
  }
}

TEST_F(OutputPathPolicyTest, ReadNeverFollowsALinkBelowTheFolder) {
  const std::string secret = tmp_.Write("outside/secret.yaml", "token: SECRET-CONTENT\n");
  fs::create_symlink(secret, root_ / "link.yaml");
  fs::create_symlink(outside_, root_ / "dir");
  fs::create_symlink("/etc/passwd", root_ / "passwd.yaml");
  for (const auto& [path, rule] : std::vector<std::pair<std::string, std::string>>{
           {"link.yaml", "is a symbolic link"},
           {"passwd.yaml", "is a symbolic link"},
           {"dir/secret.yaml", "'dir' is a symbolic link"}}) {
    const std::string m = ReadRefusal(root_, path);
    EXPECT_NE(m.find(rule), std::string::npos) << path << ": " << m;
    EXPECT_EQ(m.find("SECRET"), std::string::npos) << m;
    EXPECT_EQ(m.find("root:"), std::string::npos) << m;
  }
}

TEST_F(OutputPathPolicyTest, ReadRefusesSpecialAndOversizedFiles) {
  ASSERT_EQ(::mkfifo((root_ / "fifo.yaml").c_str(), 0600), 0);
  EXPECT_NE(ReadRefusal(root_, "fifo.yaml").find("not a regular file"), std::string::npos);
  fs::create_directories(root_ / "dir.yaml");
  EXPECT_NE(ReadRefusal(root_, "dir.yaml").find("is a folder"), std::string::npos);
  tmp_.Write("out/big.yaml", std::string(101, 'x'));
  EXPECT_NE(ReadRefusal(root_, "big.yaml", 100).find("101 bytes long, more than 100"),
            std::string::npos);
  tmp_.Write("out/ok.yaml", std::string(100, 'x'));
  EXPECT_EQ(ReadRefusal(root_, "ok.yaml", 100), "");
}

}  // namespace
}  // namespace penumbra
