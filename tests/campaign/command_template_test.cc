// method command templates without a shell (campaign/command_template.h): the word grammar,
// its refusals, values substituted as plain text into one argument each, and the quoting of
// the scripts written for people (campaign/shell_quote.h), checked against a real /bin/sh.

#include "penumbra/campaign/command_template.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <string>
#include <vector>

#include "common/temp_dir.h"
#include "penumbra/campaign/child_process.h"
#include "penumbra/campaign/method_process.h"
#include "penumbra/campaign/shell_quote.h"
#include "penumbra/core/error.h"

namespace penumbra {
namespace {

namespace fs = std::filesystem;
using testing::ReadAll;
using testing::TempDir;
using Words = std::vector<std::string>;

// the problem SplitCommandTemplate reports for `text` ("" when it accepts it)
std::string TemplateRefusal(const std::string& text) {
  try {
    SplitCommandTemplate(text);
  } catch (const ConfigError& e) {
    return e.problem();
  }
  return "";
}

// strings a shell would run, split, expand or choke on
std::vector<std::string> NastyStrings() {
  return {"",
          "plain",
          "a b",
          " leading and trailing ",
          "tab\there",
          "new\nline",
          "cr\r\nlf",
          "\x01\x02\x1b[31mred\x7f",
          "$(touch QX1)",
          "`touch QX2`",
          ";touch QX3",
          "| touch QX4",
          "&& touch QX5 &",
          "> QX6",
          "'",
          "''",
          "it's",
          "'\\''",
          "\"",
          "\\",
          "\\n",
          "trailing backslash\\",
          "$HOME ${HOME} $1 $@ $$",
          "~",
          "~root/x",
          "* ? [a] {a,b}",
          "!",
          "#comment",
          "%s %% %d",
          "--",
          "-n",
          "A=B",
          "\xff\xfe not utf-8",
          "caf\xc3\xa9 \xe2\x82\xac"};
}

TEST(CommandTemplate, SplitsWordsQuotesAndEscapes) {
  EXPECT_EQ(SplitCommandTemplate("a b\tc"), (Words{"a", "b", "c"}));
  EXPECT_EQ(SplitCommandTemplate("  a   b  "), (Words{"a", "b"}));
  EXPECT_EQ(SplitCommandTemplate("'a b' \"c d\" e\\ f"), (Words{"a b", "c d", "e f"}));
  EXPECT_EQ(SplitCommandTemplate("x'y'\"z\"w"), (Words{"xyzw"}));
  EXPECT_EQ(SplitCommandTemplate("'' \"\""), (Words{"", ""}));
  // inside single quotes everything is literal, shell operators included
  EXPECT_EQ(SplitCommandTemplate("'$(x) `y` ; | > * ~ # \\'"), (Words{"$(x) `y` ; | > * ~ # \\"}));
  // inside double quotes \" \\ \$ \` stand for the character, other backslashes stay
  EXPECT_EQ(SplitCommandTemplate("\"\\$HOME \\` \\\" \\\\ \\n\""), (Words{"$HOME ` \" \\ \\n"}));
  EXPECT_EQ(SplitCommandTemplate("\\$x \\; \\|"), (Words{"$x", ";", "|"}));
  // placeholders stay in the words; # and ~ inside a word and = after the first are literal
  EXPECT_EQ(SplitCommandTemplate("run {dataset}/associations.txt --k={fx},{fy} a#b a~b"),
            (Words{"run", "{dataset}/associations.txt", "--k={fx},{fy}", "a#b", "a~b"}));
  // a YAML block scalar's final newline
  EXPECT_EQ(SplitCommandTemplate("a b\n"), (Words{"a", "b"}));
  // a shell the user asked for, values passed as its positional arguments
  EXPECT_EQ(SplitCommandTemplate("sh -c 'slam \"$1\" > \"$2\"' sh {dataset} {output}"),
            (Words{"sh", "-c", "slam \"$1\" > \"$2\"", "sh", "{dataset}", "{output}"}));
}

TEST(CommandTemplate, RefusesWhatOnlyAShellWouldDo) {
  for (const char* t :
       {"a; b", "a;b", "a | b", "a && b", "a & ", "a > f", "a < f", "a >> f", "(a)", "a $(b)",
        "a `b`", "a $HOME", "a *", "a ?.txt", "a [x]", "a\nb", "a\rb", "a\x01"}) {
    const std::string e = TemplateRefusal(t);
    EXPECT_NE(e, "") << "accepted: " << t;
    EXPECT_NE(e.find("column "), std::string::npos) << e;
  }
  EXPECT_NE(TemplateRefusal("run {dataset} ; rm x").find("column 15: ';' separates commands"),
            std::string::npos)
      << TemplateRefusal("run {dataset} ; rm x");
  // the reported case: a placeholder in double quotes next to a command substitution
  EXPECT_NE(TemplateRefusal("run \"$(cat {dataset})\"").find("'$' inside \"...\""),
            std::string::npos)
      << TemplateRefusal("run \"$(cat {dataset})\"");
  EXPECT_NE(TemplateRefusal("run \"`x`\"").find("'`' inside"), std::string::npos);
  EXPECT_NE(TemplateRefusal("#x").find("begins a comment"), std::string::npos);
  EXPECT_NE(TemplateRefusal("run ~/x").find("home folder"), std::string::npos);
  EXPECT_NE(TemplateRefusal("run 'x").find("unterminated '"), std::string::npos);
  EXPECT_NE(TemplateRefusal("run \"x").find("unterminated \""), std::string::npos);
  EXPECT_NE(TemplateRefusal("run x\\").find("trailing \\"), std::string::npos);
  EXPECT_NE(TemplateRefusal("").find("empty"), std::string::npos);
  EXPECT_NE(TemplateRefusal(" \t ").find("empty"), std::string::npos);
  EXPECT_NE(TemplateRefusal("PYTHONPATH={pythonpath} prog").find("/usr/bin/env NAME=value"),
            std::string::npos);
  EXPECT_NE(TemplateRefusal("exec prog").find("'exec' is a shell builtin"), std::string::npos);
  EXPECT_NE(TemplateRefusal("cd {workdir}").find("'cd' is a shell builtin"), std::string::npos);
  // placeholders inside a shell's (or another interpreter's) inline program would splice
  // values into program text
  for (const char* t : {"sh -c 'slam {dataset}'", "/bin/bash -ec 'slam {dataset}' bash",
                        "bash -o pipefail -c 'a {output} | b'", "/usr/bin/env A=1 sh -c 'x {seed}'",
                        "timeout 60 sh -c 'x {seed}'",
                        "/usr/bin/python3 -u -c 'open(\"{output}\")'", "perl -e 'print {seed}'"}) {
    const std::string e = TemplateRefusal(t);
    EXPECT_NE(e.find("inside the inline program"), std::string::npos) << t << ": " << e;
  }
  // ... but not their arguments, modules or literal braces
  EXPECT_EQ(TemplateRefusal("sh -c 'slam \"$1\"' sh {dataset}"), "");
  EXPECT_EQ(TemplateRefusal("sh -c 'echo {{x}}'"), "");
  EXPECT_EQ(TemplateRefusal("python3 -c 'import sys; print(sys.argv[1])' {dataset}"), "");
  EXPECT_EQ(TemplateRefusal("/usr/bin/python3 -m penumbra_nav --c {seed}"), "");
  EXPECT_EQ(TemplateRefusal("'FOO=1' x=2 {penumbra}"), "");
}

// a shell or an interpreter reads its options and its program as code: no placeholder there,
// whatever stands before it and however its options are written; values reach it only as the
// program's arguments
TEST(CommandTemplate, NoPlaceholderReachesTheCodeOfAShellOrAnInterpreter) {
  struct Case {
    const char* text;
    const char* reason;
  };
  for (const Case& c : std::vector<Case>{
           // the two reported templates: `--` ended the old option scan, -m stopped it
           {"sh -c -- 'true {output}'",
            "word 4 'true {output}': a placeholder inside the inline "
            "program of 'sh -c'"},
           {"python3 -m timeit -s 'os.system(\"cat {dataset} > {output}\")'",
            "'python3 -m timeit' runs its arguments as code"},
           {"python3 -m timeit -s {output}", "'python3 -m timeit' runs its arguments as code"},
           {"/usr/bin/python3 -mtimeit {dataset}", "runs its arguments as code"},
           {"python3 -m pdb script.py {output}", "runs its arguments as code"},
           // the script itself a value, with and without -c
           {"sh -c {output}", "inside the inline program of 'sh -c'"},
           {"bash -e -- {output}", "as the program 'bash' runs"},
           {"sh {output}", "as the program 'sh' runs"},
           {"sh +s {output}", "as the program 'sh' runs"},
           {"perl {dataset}", "as the program 'perl' runs"},
           {"awk {output}", "as the program 'awk' runs"},
           // behind wrappers, wherever the shell stands
           {"env -i sh -c -- 'x {seed}'", "inside the inline program of 'sh -c'"},
           {"/usr/bin/env A=1 dash -c 'x {seed}'", "inside the inline program of 'dash -c'"},
           {"nice -n 5 timeout 60 stdbuf -oL zsh -c 'x {seed}'", "inside the inline program"},
           {"xargs sh -c {output}", "inside the inline program of 'sh -c'"},
           {"find . -exec bash -c 'x {output}' bash \\;", "inside the inline program of 'bash -c'"},
           {"sh -c 'exec \"$@\"' sh sh -c {output}", "inside the inline program of 'sh -c'"},
           // option clusters and attached code
           {"bash -o pipefail -ec 'a {output}'", "inside the inline program of 'bash -c'"},
           {"python3 -uc 'open(\"{output}\")'", "inside the inline program of 'python3 -uc'"},
           {"python3 -c{output}", "inside the inline program of 'python3 -c'"},
           {"python3 -W {output} script.py", "in an option of 'python3'"},
           {"perl -lne {output}", "inside the inline program of 'perl -lne'"},
           {"ruby -e {output}", "inside the inline program of 'ruby -e'"},
           {"node --eval={output}", "inside the inline program of 'node --eval'"},
           {"node -p {output}", "inside the inline program of 'node -p'"},
           {"php -r {output}", "inside the inline program of 'php -r'"},
           {"sed -e {output} f", "inside the inline program of 'sed -e'"},
           {"env -S{output} x", "inside the inline program of 'env -S'"},
           // programs that hand their arguments to a shell as text
           {"ssh host slam {output}", "'ssh' hands its arguments to a shell"},
           {"watch -n 1 slam {output}", "'watch' hands its arguments to a shell"},
           {"make -C src OUT={output}", "'make' hands its arguments to a shell"},
       }) {
    const std::string e = TemplateRefusal(c.text);
    EXPECT_NE(e, "") << "accepted: " << c.text;
    EXPECT_NE(e.find(c.reason), std::string::npos) << c.text << ": " << e;
    EXPECT_NE(e.find("column "), std::string::npos) << c.text << ": " << e;
  }
  EXPECT_NE(TemplateRefusal("sh -c -- 'true {output}'").find("column 10: word 4"),
            std::string::npos)
      << TemplateRefusal("sh -c -- 'true {output}'");
  // values after the program are its arguments: "$1", sys.argv, @ARGV, process.argv
  for (const char* t :
       {"sh -c 'slam \"$1\" > \"$2\"' sh {dataset} {output}", "sh -c -- 'slam \"$1\"' sh {dataset}",
        "/usr/bin/env A=1 nice -n 5 bash -ec 'x \"$1\"' bash {seed}", "sh -o pipefail -s {output}",
        "sh script.sh {output}",
        "python3 -c 'import sys; print(sys.argv[1])' {dataset} --out={output}",
        "python3 -W ignore -u script.py {dataset}", "/usr/bin/python3 -m penumbra_nav --c {seed}",
        "perl -0777 -ne 'print' {dataset}/x.txt", "perl -e 'print $ARGV[0]' {seed}",
        "ruby -e 'p ARGV' {seed}", "node --eval 'x' {output}", "awk -f prog.awk {dataset}/a.txt",
        "awk '{{print $1}}' {dataset}/a.txt", "sed s/a/b/ {dataset}/x",
        "env -u HOME PYTHONPATH={workdir} prog {output}"})
    EXPECT_EQ(TemplateRefusal(t), "") << t;
}

// a placeholder is a whole argument or has a fixed plain prefix or suffix: never part of a
// longer text a program parses, and two values never run together
TEST(CommandTemplate, APlaceholderIsAWholeWordOrHasAPlainPrefixOrSuffix) {
  for (const char* t :
       {"run '{dataset}/my file'", "run --json '{{\"seed\": {seed}}}'", "run 'x;{seed}'",
        "run \"a {output}\"", "tool -e 'print({seed})'", "run '$({output})'"}) {
    const std::string e = TemplateRefusal(t);
    EXPECT_NE(e.find("holds a placeholder beside"), std::string::npos) << t << ": " << e;
  }
  EXPECT_NE(TemplateRefusal("run {dataset}{output}").find("two placeholders with nothing between"),
            std::string::npos);
  EXPECT_NE(TemplateRefusal("run {dataset").find("unmatched '{'"), std::string::npos);
  EXPECT_NE(TemplateRefusal("run x}").find("unmatched '}'"), std::string::npos);
  for (const char* t :
       {"run {output}", "run --out={output}", "run {dataset}/rgb.txt", "run {fx},{fy},{cx},{cy}",
        "run x{seed}y", "run -o:{output}@2%", "run '{{literal}}' 'a b' {output}"})
    EXPECT_EQ(TemplateRefusal(t), "") << t;
}

// the templates of the docs (benchmarks.md) and the bundled methods still split, as before
TEST(CommandTemplate, DocumentedAndBundledTemplatesAreAccepted) {
  for (const char* t :
       {"my_slam --images {dataset} --out {output} --fx {fx} --fy {fy} --cx {cx} --cy {cy}",
        "/opt/slam/run --images {dataset}/rgb 'two words' --fx={fx} \"{output}\"",
        "sh -c 'my_slam --images \"$1\" | tee slam.log > \"$2\"' sh {dataset} {output}",
        "/usr/bin/env OMP_NUM_THREADS=1 /opt/slam/run {dataset} {output}",
        "/opt/ORB_SLAM2/Examples/RGB-D/rgbd_tum /opt/ORB_SLAM2/Vocabulary/ORBvoc.txt "
        "/opt/settings/penumbra_rgbd.yaml {dataset} {dataset}/associations.txt",
        "/opt/ORB_SLAM3/Examples/Monocular/mono_tum /opt/ORB_SLAM3/Vocabulary/ORBvoc.txt "
        "/opt/settings/penumbra_mono3.yaml {dataset}",
        "my_nav --connect {endpoint} --goal {goal_x} {goal_y} --log {out_dir}/log.txt",
        "{penumbra} slam opencv_rgbd {dataset} {output} --intrinsics {fx},{fy},{cx},{cy}",
        "/usr/bin/env PYTHONPATH={pythonpath} /usr/bin/python3 -m penumbra_nav --endpoint "
        "{endpoint} --goal {goal_x} {goal_y} --radius {radius} --timeout {timeout_sec} --robot "
        "{robot} --robot-name {robot_name} --out {out_dir}/episode.json"})
    EXPECT_EQ(TemplateRefusal(t), "") << t;
  EXPECT_EQ(SplitCommandTemplate("sh -c -- 'slam \"$1\"' sh {dataset}"),
            (Words{"sh", "-c", "--", "slam \"$1\"", "sh", "{dataset}"}));
}

TEST(CommandTemplate, ValuesBecomeOneLiteralArgumentEach) {
  const Words words =
      SplitCommandTemplate("prog {dataset} \"{dataset}\" '{output}' x{seed}y {{z}}");
  for (const std::string& v : NastyStrings()) {
    const Words argv = ExpandCommandTemplate(words, {{"dataset", v}, {"output", v}, {"seed", v}});
    EXPECT_EQ(argv, (Words{"prog", v, v, v, "x" + v + "y", "{z}"})) << v;
  }
  EXPECT_THROW(ExpandCommandTemplate({"{nope}"}, {{"dataset", "x"}}), Error);
}

TEST(CommandTemplate, MethodGetsInjectedTextLiterallyAndNothingRuns) {
  TempDir dir;
  const Words words =
      SplitCommandTemplate("/usr/bin/printf '%s\\n' {dataset} \"{dataset}\" x{output}y");
  const std::string dataset = dir.str() + "/d $(touch QX1) `touch QX2` ;touch QX3 'q\"";
  const std::string output = ";touch QX4 | touch QX5 && touch QX6";
  const Words argv = ExpandCommandTemplate(words, {{"dataset", dataset}, {"output", output}});
  const fs::path work = dir.path() / "work";
  const ProcessOutcome o = RunMethodCommand(argv, work.string(), 30);
  ASSERT_TRUE(o.ok()) << o.Describe() << ReadAll(work / "stderr.log");
  EXPECT_EQ(ReadAll(work / "stdout.log"), dataset + "\n" + dataset + "\n" + "x" + output + "y\n");
  for (const char* f : {"QX1", "QX2", "QX3", "QX4", "QX5", "QX6"}) {
    EXPECT_FALSE(fs::exists(work / f)) << f;
    EXPECT_FALSE(fs::exists(dir.path() / f)) << f;
  }
}

TEST(CommandTemplate, ProgramThatCannotStartIsAnOutcomeWithItsReason) {
  TempDir dir;
  ProcessOutcome o = RunMethodCommand({"penumbra-no-such-program"}, dir.str(), 30);
  EXPECT_EQ(o.exit_code, 127);
  EXPECT_FALSE(o.ok());
  EXPECT_NE(
      o.Describe().find("cannot run 'penumbra-no-such-program' (searched PATH): No such file"),
      std::string::npos)
      << o.Describe();
  o = RunMethodCommand({(dir.path() / "missing").string()}, dir.str(), 30);
  EXPECT_NE(o.Describe().find("No such file"), std::string::npos) << o.Describe();
  // PATH is searched: `true` runs from /usr/bin or /bin
  EXPECT_TRUE(RunMethodCommand({"true"}, dir.str(), 30).ok());
}

TEST(MethodProcessOutcome, ExitSignalTimeoutAndWorkFolder) {
  TempDir dir;
  ProcessOutcome o = RunMethodCommand({"/bin/sh", "-c", "echo hi; exit 4"}, dir.str(), 10);
  EXPECT_EQ(o.exit_code, 4);
  EXPECT_FALSE(o.ok());
  EXPECT_EQ(ReadAll(dir.path() / "stdout.log"), "hi\n");
  o = RunMethodCommand({"/bin/sh", "-c", "kill -SEGV $$"}, dir.str(), 10);
  EXPECT_EQ(o.signal, 11);
  EXPECT_EQ(o.Describe(), "signal 11 (SIGSEGV)");
  o = RunMethodCommand({"sleep", "30"}, dir.str(), 0.3);
  EXPECT_TRUE(o.timed_out);
  EXPECT_LT(o.wall_sec, 10);
  o = RunMethodCommand({"/bin/sh", "-c", "pwd > here.txt"}, (dir.path() / "w").string(), 10);
  EXPECT_TRUE(o.ok());
  EXPECT_EQ(ReadAll(dir.path() / "w" / "here.txt"), (dir.path() / "w").string() + "\n");
}

TEST(ShellQuote, RoundTripsNastyStringsThroughARealShell) {
  TempDir dir;
  EXPECT_EQ(ShellQuote("it's"), "'it'\\''s'");
  EXPECT_EQ(ShellQuote(""), "''");
  EXPECT_THROW(ShellQuote(std::string("a\0b", 3)), Error);
  for (const char* shell : {"/bin/sh", "/bin/bash"}) {
    for (const std::string& s : NastyStrings()) {
      const std::string script = "cd " + ShellQuote(dir.str()) + " && printf %s " + ShellQuote(s);
      int code = -1;
      const std::optional<std::string> got = CaptureCommand({shell, "-c", script}, false, &code);
      ASSERT_TRUE(got) << shell << " exit " << code << " for " << SanitizeForMessage(s);
      EXPECT_EQ(*got, s) << shell << ": " << SanitizeForMessage(s);
    }
  }
  // every injection attempt stayed text
  for (const char* f : {"QX1", "QX2", "QX3", "QX4", "QX5", "QX6"})
    EXPECT_FALSE(fs::exists(dir.path() / f)) << f;
}

TEST(ShellQuote, CommandScriptRunsTheSameArgumentVector) {
  TempDir dir;
  Words argv = {"/usr/bin/printf", "%s\\0"};
  for (const std::string& s : NastyStrings()) argv.push_back(s);
  const fs::path work = dir.path() / "w $(touch QX1) 'x";
  fs::create_directories(work);
  const std::string script = dir.Write("command.sh", MethodCommandScript(argv, work.string()));
  const std::optional<std::string> got = CaptureCommand({"/bin/sh", script});
  ASSERT_TRUE(got);
  Words printed;
  size_t pos = 0;
  while (pos < got->size()) {
    const size_t end = got->find('\0', pos);
    ASSERT_NE(end, std::string::npos);
    printed.push_back(got->substr(pos, end - pos));
    pos = end + 1;
  }
  EXPECT_EQ(printed, Words(argv.begin() + 2, argv.end()));
  EXPECT_FALSE(fs::exists(dir.path() / "QX1"));
  EXPECT_FALSE(fs::exists(work / "QX1"));
  // plain words stay readable; a first word holding '=' is quoted (not an assignment)
  EXPECT_EQ(ShellCommandLine({"/usr/bin/x", "--a=1", "b c", "it's"}),
            "/usr/bin/x --a=1 'b c' 'it'\\''s'");
  EXPECT_EQ(ShellCommandLine({"A=B", "x"}), "'A=B' x");
}

TEST(ShellQuote, FindsControlCharacters) {
  EXPECT_FALSE(FindControlCharacter("/tmp/a b/c'd\xc3\xa9"));
  EXPECT_EQ(FindControlCharacter("ab\ncd"), 2u);
  EXPECT_EQ(FindControlCharacter("\r"), 0u);
  EXPECT_EQ(FindControlCharacter(std::string("x\0", 2)), 1u);
  EXPECT_EQ(FindControlCharacter("a\tb"), 1u);
  EXPECT_EQ(FindControlCharacter("a\x7f"), 1u);
  EXPECT_EQ(FindControlCharacter("a\x1f"), 1u);
}

}  // namespace
}  // namespace penumbra
