#include "penumbra/campaign/command_template.h"

#include <algorithm>
#include <array>
#include <string_view>

#include "penumbra/core/error.h"

namespace penumbra {
namespace {

// a refusal at 0-based byte `i` of the template
[[noreturn]] void Refuse(size_t i, const std::string& problem) {
  throw ConfigError("", 0, "", "column " + std::to_string(i + 1) + ": " + problem);
}

std::string Shown(char c) {
  const unsigned char u = static_cast<unsigned char>(c);
  if (u < 0x20 || u == 0x7f) {
    static const char kHex[] = "0123456789abcdef";
    return std::string("byte 0x") + kHex[u >> 4] + kHex[u & 15];
  }
  return std::string("'") + c + "'";
}

// what an unquoted operator character would do in a shell
std::string_view OperatorMeaning(char c) {
  switch (c) {
    case ';':
    case '&':
      return "separates commands";
    case '|':
      return "makes a pipeline";
    case '<':
    case '>':
      return "redirects";
    case '(':
    case ')':
      return "starts a subshell";
    case '$':
      return "expands a variable or command";
    case '`':
      return "substitutes a command";
    case '*':
    case '?':
    case '[':
      return "is a file-name pattern";
    default:
      return "";
  }
}

// builtins and keywords: the first word of a command run without a shell cannot be one
bool ShellBuiltin(const std::string& w) {
  static constexpr std::array<std::string_view, 28> kNames = {
      "exec", "cd",   "export", "set",      "unset", "source", ".",     "eval", "ulimit", "umask",
      "if",   "then", "else",   "fi",       "for",   "while",  "until", "do",   "done",   "case",
      "esac", "!",    "{",      "function", "alias", "trap",   "read",  "local"};
  return std::find(kNames.begin(), kNames.end(), w) != kNames.end();
}

bool IsAssignment(const std::string& raw_word) {
  const size_t eq = raw_word.find('=');
  if (eq == std::string::npos || eq == 0) return false;
  return std::all_of(raw_word.begin(), raw_word.begin() + static_cast<long>(eq), [](char c) {
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_';
  });
}

bool HasPlaceholder(const std::string& w) {
  for (size_t i = 0; i < w.size(); ++i) {
    if (w[i] != '{') continue;
    if (i + 1 < w.size() && w[i + 1] == '{') {
      ++i;
      continue;
    }
    return true;
  }
  return false;
}

// the characters a word may hold beside its placeholders: those a shell never reads
bool PlainChar(char c) {
  return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
         std::string_view("_-./,:+=@%").find(c) != std::string_view::npos;
}

std::string WordShown(const std::string& w) { return "'" + SanitizeForMessage(w, 60) + "'"; }

// a refusal about word `k`, which begins at 0-based byte `col` of the template
[[noreturn]] void RefuseWord(const std::vector<size_t>& cols, size_t k,
                             const std::string& problem) {
  Refuse(cols[k], "word " + std::to_string(k + 1) + " " + problem);
}

// the braces of each word: {{ and }} are literal, {name} a placeholder; a lone brace and two
// placeholders with nothing between them are refused. a word holding a placeholder holds
// nothing else but plain characters (PlainChar): a placeholder is a whole argument or one with a
// fixed prefix or suffix (--out={output}, {dataset}/rgb.txt), never part of a text a program
// parses (a script, code, a list of words)
void CheckPlaceholderWords(const std::vector<std::string>& words, const std::vector<size_t>& cols) {
  for (size_t k = 0; k < words.size(); ++k) {
    const std::string& w = words[k];
    bool placeholder = false, literal_brace = false;
    char other = 0;
    size_t prev_end = std::string::npos;  // index just past the last placeholder
    for (size_t i = 0; i < w.size(); ++i) {
      const char c = w[i];
      if ((c == '{' || c == '}') && i + 1 < w.size() && w[i + 1] == c) {
        literal_brace = true;
        ++i;
        continue;
      }
      if (c == '}')
        RefuseWord(cols, k, WordShown(w) + ": an unmatched '}'; write '}}' for a brace");
      if (c == '{') {
        const size_t end = w.find('}', i);
        if (end == std::string::npos)
          RefuseWord(cols, k, WordShown(w) + ": an unmatched '{'; write '{{' for a brace");
        if (prev_end == i)
          RefuseWord(cols, k,
                     WordShown(w) +
                         ": two placeholders with nothing between them merge two values into "
                         "one; expected a separator (such as , or /) between them");
        placeholder = true;
        prev_end = end + 1;
        i = end;
        continue;
      }
      if (!PlainChar(c) && other == 0) other = c;
    }
    if (!placeholder || (other == 0 && !literal_brace)) continue;
    const std::string what = literal_brace ? std::string("a literal brace") : Shown(other);
    RefuseWord(cols, k,
               WordShown(w) + " holds a placeholder beside " + what +
                   ", which would make a value part of a longer text (a script, code or a list "
                   "a program parses); expected a placeholder as a whole argument, or with only "
                   "letters, digits and _ - . / , : + = @ % around it (--out={output}, "
                   "{dataset}/rgb.txt); pass values to a script as its arguments");
  }
}

// how a shell or interpreter takes its program, for the words after its name
struct Syntax {
  std::string_view code{};           // short flags whose argument is program text
  std::string_view file{};           // short flags whose argument is the program's file
  std::string_view takes_arg{};      // short flags with an argument (attached or the next word)
  std::string_view attached_only{};  // short flags whose argument is the rest of the cluster
  std::string_view no_program{};     // short flags after which no operand is the program
  std::vector<std::string_view> long_code{}, long_file{}, long_arg{};
  bool plus_options = false;       // +o style options (shells)
  bool code_ends_options = false;  // the words after the code are its arguments (python -c)
  bool operand_is_program = true;  // without a code or file flag, the first operand is one
  bool shell = false;              // -c makes the first operand a script; the next is $0
  bool python = false;             // -m MODULE
};

const Syntax kShell{.takes_arg = "oO",
                    .no_program = "s",
                    .long_arg = {"--rcfile", "--init-file"},
                    .plus_options = true,
                    .shell = true};
const Syntax kPython{.code = "c",
                     .takes_arg = "WXQ",
                     .long_arg = {"--check-hash-based-pycs"},
                     .code_ends_options = true,
                     .python = true};
const Syntax kPerl{.code = "eE", .attached_only = "iImMxdDCF"};
const Syntax kRuby{.code = "e", .takes_arg = "rICE", .attached_only = "xKTFW"};
const Syntax kNode{.code = "ep",
                   .takes_arg = "r",
                   .long_code = {"--eval", "--print"},
                   .long_arg = {"--require", "--import", "--input-type", "--loader",
                                "--experimental-loader", "--conditions", "--title"}};
const Syntax kPhp{.code = "rBRE", .file = "fF", .takes_arg = "cdz"};
const Syntax kLua{.code = "e", .takes_arg = "l"};
const Syntax kJulia{.code = "eE", .takes_arg = "JLtp", .long_code = {"--eval", "--print"}};
const Syntax kTcl{.code = "c"};
const Syntax kAwk{.code = "e",
                  .file = "fEi",
                  .takes_arg = "vFl",
                  .long_code = {"--source"},
                  .long_file = {"--file", "--exec", "--include"},
                  .long_arg = {"--assign", "--field-separator", "--load"}};
const Syntax kSed{.code = "e",
                  .file = "f",
                  .takes_arg = "l",
                  .attached_only = "i",
                  .long_code = {"--expression"},
                  .long_file = {"--file"}};
// env: -S splits its argument into words (a value there would be split); its first operand
// (NAME=value or the program) is no program text
const Syntax kEnv{.code = "S",
                  .takes_arg = "uCP",
                  .long_code = {"--split-string"},
                  .long_arg = {"--unset", "--chdir"},
                  .operand_is_program = false};

// `base` is `name` with an optional version suffix (python3.11, perl5.36, lua5.4)
bool Versioned(std::string_view base, std::string_view name) {
  if (base.rfind(name, 0) != 0) return false;
  return base.substr(name.size()).find_first_not_of("0123456789.") == std::string_view::npos;
}

// programs that hand their arguments, joined, to a shell or another interpreter (ssh's remote
// shell, watch's sh -c, su -c, make's variables, GNU parallel, ...): no placeholder after them
bool HandsArgumentsToAShell(std::string_view base) {
  static constexpr std::array<std::string_view, 17> kNames = {
      "ssh",    "watch", "su",    "runuser",  "sudo", "doas",       "script", "flock", "tmux",
      "screen", "make",  "gmake", "parallel", "pwsh", "powershell", "expect", "gdb"};
  return std::find(kNames.begin(), kNames.end(), base) != kNames.end();
}

const Syntax* SyntaxOf(std::string_view base) {
  for (std::string_view s : {"sh", "bash", "rbash", "dash", "zsh", "ksh", "ksh93", "mksh", "ash",
                             "yash", "posh", "fish", "csh", "tcsh"})
    if (base == s) return &kShell;
  if (Versioned(base, "python") || Versioned(base, "pypy")) return &kPython;
  if (Versioned(base, "perl")) return &kPerl;
  if (Versioned(base, "ruby")) return &kRuby;
  if (base == "node" || base == "nodejs") return &kNode;
  if (Versioned(base, "php")) return &kPhp;
  if (Versioned(base, "lua") || Versioned(base, "luajit")) return &kLua;
  if (base == "Rscript" || base == "osascript") return &kLua;  // -e CODE, or a script file
  if (Versioned(base, "julia")) return &kJulia;
  if (Versioned(base, "tclsh") || Versioned(base, "wish")) return &kTcl;
  for (std::string_view s : {"awk", "gawk", "mawk", "nawk", "busybox-awk"})
    if (base == s) return &kAwk;
  if (base == "sed" || base == "gsed") return &kSed;
  if (base == "env") return &kEnv;
  return nullptr;
}

// python modules that run their arguments as code or as another program
bool ModuleRunsItsArguments(const std::string& module) {
  for (std::string_view m : {"timeit", "pdb", "cProfile", "profile", "trace", "code", "runpy",
                             "doctest", "idlelib", "IPython", "ipdb", "pip"})
    if (module == m) return true;
  return false;
}

const std::string kPassValues =
    "pass values as arguments after the program and read them there (sh -c 'slam \"$1\" > "
    "\"$2\"' sh {dataset} {output}; python3 -c '...sys.argv[1]...' {dataset}), or write a script "
    "file that takes them as arguments";

// the words from `i` (a shell or interpreter) on: its options and the program it runs (inline
// code, a script file, a module) may not hold a placeholder; only the program's arguments may.
// returns the index of the last word checked here (with a shell's -c, its $0 word after the
// script, which the caller does not read as a program name)
size_t CheckInterpreter(const std::vector<std::string>& words, const std::vector<size_t>& cols,
                        size_t i, const std::string& base, const Syntax& s) {
  const size_t n = words.size();
  const std::string& name = words[i];
  bool program_given = false, no_program = false, shell_c = false;
  size_t program = n;     // the word holding the program text or file, n when none
  std::string flag_word;  // the option word that gave it
  size_t last = i;        // words (i, last] are options, their arguments and the program
  size_t j = i + 1;
  const auto in = [](std::string_view set, char c) {
    return set.find(c) != std::string_view::npos;
  };
  const auto listed = [](const std::vector<std::string_view>& v, std::string_view w) {
    return std::find(v.begin(), v.end(), w) != v.end();
  };
  while (j < n) {
    const std::string& w = words[j];
    if (w == "--") {
      last = j++;
      break;
    }
    const bool option = w.size() >= 2 && (w[0] == '-' || (s.plus_options && w[0] == '+'));
    if (!option) break;
    last = j;
    if (w[1] == '-') {
      const size_t eq = w.find('=');
      const std::string_view opt = std::string_view(w).substr(0, eq);
      const bool attached = eq != std::string::npos;
      if (listed(s.long_code, opt) || listed(s.long_file, opt)) {
        program_given = true;
        flag_word = std::string(opt);
        program = attached ? j : std::min(j + 1, n - 1);
        if (!attached && j + 1 < n) last = ++j;
      } else if (listed(s.long_arg, opt) && !attached && j + 1 < n) {
        last = ++j;
      }
      ++j;
      if (program_given && s.code_ends_options) break;
      continue;
    }
    bool module = false;
    std::string module_name;
    for (size_t k = 1; k < w.size(); ++k) {
      const char c = w[k];
      const bool rest = k + 1 < w.size();
      if (s.shell && c == 'c') shell_c = true;
      if (s.python && c == 'm') {
        module = true;
        program_given = true;
        flag_word = w.substr(0, k + 1);
        program = rest ? j : std::min(j + 1, n - 1);
        module_name = rest ? w.substr(k + 1) : j + 1 < n ? words[j + 1] : "";
        if (!rest && j + 1 < n) last = ++j;
        break;
      }
      if (in(s.code, c) || in(s.file, c)) {
        program_given = true;
        flag_word = w.substr(0, k + 1);
        program = rest ? j : std::min(j + 1, n - 1);
        if (!rest && j + 1 < n) last = ++j;
        break;
      }
      if (in(s.takes_arg, c)) {
        if (!rest && j + 1 < n) last = ++j;
        break;
      }
      if (in(s.attached_only, c)) break;
      if (in(s.no_program, c) && w[0] == '-') no_program = true;
    }
    ++j;
    if (module) {
      const std::string& mod = module_name;
      if (ModuleRunsItsArguments(mod))
        for (size_t k = program + 1; k < n; ++k)
          if (HasPlaceholder(words[k]))
            RefuseWord(cols, k,
                       WordShown(words[k]) + ": '" + SanitizeForMessage(name, 60) + " -m " +
                           SanitizeForMessage(mod, 60) +
                           "' runs its arguments as code or as another program, and a "
                           "placeholder there would put a value into program text; expected "
                           "no placeholder after it (" +
                           kPassValues + ")");
      break;
    }
    if (program_given && s.code_ends_options) break;
  }
  if (!program_given && !no_program && s.operand_is_program && j < n) {
    program = j;
    last = j;
    flag_word = shell_c ? "-c" : "";
  }
  for (size_t k = i + 1; k <= last && k < n; ++k) {
    if (!HasPlaceholder(words[k])) continue;
    if (k == program && !flag_word.empty())
      RefuseWord(cols, k,
                 WordShown(words[k]) + ": a placeholder inside the inline program of '" +
                     SanitizeForMessage(name, 60) + " " + SanitizeForMessage(flag_word, 20) +
                     "' would put a value into program text; " + kPassValues);
    if (k == program)
      RefuseWord(cols, k,
                 WordShown(words[k]) + ": a placeholder as the program '" +
                     SanitizeForMessage(base, 60) +
                     "' runs would make a value its code or its script; expected a fixed "
                     "script, then placeholders as its arguments");
    RefuseWord(cols, k,
               WordShown(words[k]) + ": a placeholder in an option of '" +
                   SanitizeForMessage(name, 60) +
                   "' (before the program it runs) can become program text or be split; "
                   "expected placeholders only after the program, as its arguments");
  }
  // sh -c SCRIPT NAME ...: NAME is $0, not a program
  if (shell_c && program != n && program + 1 < n) return program + 1;
  return last;
}

// every word naming a shell or an interpreter, wherever it stands (after env, nice, timeout,
// xargs, find -exec, ...), starts a program that reads code: see CheckInterpreter
void CheckInterpreters(const std::vector<std::string>& words, const std::vector<size_t>& cols) {
  for (size_t i = 0; i < words.size(); ++i) {
    const std::string& w = words[i];
    const std::string base = w.substr(w.rfind('/') == std::string::npos ? 0 : w.rfind('/') + 1);
    if (HandsArgumentsToAShell(base)) {
      for (size_t k = i + 1; k < words.size(); ++k)
        if (HasPlaceholder(words[k]))
          RefuseWord(cols, k,
                     WordShown(words[k]) + ": '" + SanitizeForMessage(w, 60) +
                         "' hands its arguments to a shell or another interpreter as text, and "
                         "a placeholder after it would put a value into program text; expected "
                         "no placeholder after it (run a script that takes values as its "
                         "arguments)");
      return;
    }
    if (const Syntax* s = SyntaxOf(base)) i = CheckInterpreter(words, cols, i, base, *s);
  }
}

}  // namespace

std::vector<std::string> SplitCommandTemplate(const std::string& input) {
  std::string text = input;
  while (!text.empty() && text.back() == '\n') text.pop_back();
  std::vector<std::string> words;
  std::vector<bool> first_quoted;  // whether a word's text began inside quotes
  std::vector<size_t> cols;        // the 0-based byte where each word begins
  size_t word_col = 0;
  std::string cur;
  bool in_word = false, quoted_start = false;
  for (size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (c == ' ' || c == '\t') {
      if (in_word) {
        words.push_back(cur);
        first_quoted.push_back(quoted_start);
        cols.push_back(word_col);
        cur.clear();
        in_word = false;
      }
      continue;
    }
    const bool word_start = !in_word;
    if (word_start) {
      quoted_start = c == '\'' || c == '"';
      word_col = i;
    }
    in_word = true;
    if (c == '\'') {
      const size_t end = text.find('\'', i + 1);
      if (end == std::string::npos) Refuse(i, "unterminated '; expected a closing '");
      cur += text.substr(i + 1, end - i - 1);
      i = end;
      continue;
    }
    if (c == '"') {
      size_t k = i + 1;
      for (; k < text.size() && text[k] != '"'; ++k) {
        const char d = text[k];
        if (d == '\\' && k + 1 < text.size() && text[k + 1] == '\n')
          Refuse(k + 1, "a line continuation (\\ and a newline); expected one line");
        if (d == '\\' && k + 1 < text.size() &&
            std::string_view("\"\\$`").find(text[k + 1]) != std::string_view::npos) {
          cur += text[++k];
          continue;
        }
        if (d == '$' || d == '`')
          Refuse(k, Shown(d) + " inside \"...\" " + std::string(OperatorMeaning(d)) +
                        " in a shell, and nothing is expanded here; write \\" + d +
                        " or put it in '...' for the literal character");
        cur += d;
      }
      if (k >= text.size()) Refuse(i, "unterminated \"; expected a closing \"");
      i = k;
      continue;
    }
    if (c == '\\') {
      if (i + 1 >= text.size()) Refuse(i, "a trailing \\ escapes nothing");
      const char next = text[i + 1];
      if (next == '\n') Refuse(i + 1, "a newline; expected one command on one line");
      cur += next;
      ++i;
      continue;
    }
    const unsigned char u = static_cast<unsigned char>(c);
    if (c == '\n' || c == '\r')
      Refuse(i,
             "a line break separates commands in a shell; expected one command (write sh -c "
             "'...' for a script)");
    if (u < 0x20 || u == 0x7f)
      Refuse(i, "a control character (" + Shown(c) + "); expected printable text");
    const std::string_view meaning = OperatorMeaning(c);
    if (!meaning.empty())
      Refuse(i, Shown(c) + " " + std::string(meaning) +
                    " in a shell, and the command runs without one; put it in '...' for the "
                    "literal character, or write sh -c '...' for a shell");
    if (word_start && (c == '#' || c == '~'))
      Refuse(i, Shown(c) + (c == '#' ? " begins a comment" : " names a home folder") +
                    " in a shell, and nothing is expanded here; put it in '...' for the literal "
                    "character");
    cur += c;
  }
  if (in_word) {
    words.push_back(cur);
    first_quoted.push_back(quoted_start);
    cols.push_back(word_col);
  }
  if (words.empty()) throw ConfigError("", 0, "", "empty; expected a command line");
  if (!first_quoted[0] && IsAssignment(words[0]))
    throw ConfigError("", 0, "",
                      "'" + words[0].substr(0, words[0].find('=')) +
                          "=...' sets a variable in a shell, and the command runs without one; "
                          "write /usr/bin/env NAME=value PROGRAM ...");
  if (!first_quoted[0] && ShellBuiltin(words[0]))
    throw ConfigError("", 0, "",
                      "'" + words[0] +
                          "' is a shell builtin or keyword, and the command runs without a "
                          "shell; expected a program (drop '" +
                          words[0] + "', or write sh -c '...')");
  CheckInterpreters(words, cols);
  CheckPlaceholderWords(words, cols);
  return words;
}

std::string FillTemplate(const std::string& text,
                         const std::map<std::string, std::string>& values) {
  std::string out;
  for (size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if ((c == '{' || c == '}') && i + 1 < text.size() && text[i + 1] == c) {
      out += c;
      ++i;
      continue;
    }
    if (c != '{') {
      out += c;
      continue;
    }
    const size_t end = text.find('}', i);
    const std::string key = end == std::string::npos ? "" : text.substr(i + 1, end - i - 1);
    const auto it = values.find(key);
    if (it == values.end())
      throw Error("command template: unknown placeholder '{" + SanitizeForMessage(key, 40) + "}'");
    out += it->second;
    i = end;
  }
  return out;
}

std::vector<std::string> ExpandCommandTemplate(const std::vector<std::string>& words,
                                               const std::map<std::string, std::string>& values) {
  std::vector<std::string> argv;
  argv.reserve(words.size());
  for (const std::string& w : words) argv.push_back(FillTemplate(w, values));
  return argv;
}

}  // namespace penumbra
