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

// interpreters that take a program as an argument: what kind, by the program's file name
enum class Interpreter { kNone, kShell, kPython, kOther };

Interpreter InterpreterOf(const std::string& w) {
  const std::string base = w.substr(w.rfind('/') == std::string::npos ? 0 : w.rfind('/') + 1);
  for (std::string_view s : {"sh", "bash", "dash", "zsh", "ksh", "mksh", "ash"})
    if (base == s) return Interpreter::kShell;
  if (base.rfind("python", 0) == 0) return Interpreter::kPython;
  for (std::string_view s : {"perl", "ruby", "node", "nodejs"})
    if (base == s) return Interpreter::kOther;
  return Interpreter::kNone;
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

// an interpreter given its program inline (sh -c SCRIPT, python3 -c CODE, perl -e CODE, ...):
// the program text must not hold a placeholder, values go in as its arguments
void CheckInlinePrograms(const std::vector<std::string>& words) {
  for (size_t i = 0; i < words.size(); ++i) {
    const Interpreter kind = InterpreterOf(words[i]);
    if (kind == Interpreter::kNone) continue;
    for (size_t j = i + 1; j < words.size(); ++j) {
      const std::string& o = words[j];
      const bool option =
          o.size() >= 2 && (o[0] == '-' || (kind == Interpreter::kShell && o[0] == '+'));
      if (!option || o == "--" || o[1] == '-') break;
      if (kind == Interpreter::kShell && (o == "-o" || o == "+o")) {
        ++j;
        continue;
      }
      if (kind == Interpreter::kPython && o == "-m") break;
      if (kind == Interpreter::kPython && (o == "-W" || o == "-X")) {
        ++j;
        continue;
      }
      // the flag that makes the next word the program: -c in a shell's option cluster
      // (-ec), python's -c (or a cluster ending in it: -uc), -e / -E for perl, ruby, node
      const bool inline_flag = kind == Interpreter::kShell ? o.find('c') != std::string::npos
                               : kind == Interpreter::kPython
                                   ? o.back() == 'c' && o.find_first_of("=:WX") == std::string::npos
                                   : o.find_first_of("eE") != std::string::npos;
      if (!inline_flag) continue;
      if (j + 1 < words.size() && HasPlaceholder(words[j + 1]))
        throw ConfigError(
            "", 0, "",
            "a placeholder inside the inline program of '" + words[i] + " " + o +
                "' would put a value into program text; pass values as arguments after it "
                "and read them there (sh -c 'slam \"$1\" > \"$2\"' sh {dataset} {output}; "
                "python3 -c '...sys.argv[1]...' {dataset})");
      break;
    }
  }
}

}  // namespace

std::vector<std::string> SplitCommandTemplate(const std::string& input) {
  std::string text = input;
  while (!text.empty() && text.back() == '\n') text.pop_back();
  std::vector<std::string> words;
  std::vector<bool> first_quoted;  // whether a word's text began inside quotes
  std::string cur;
  bool in_word = false, quoted_start = false;
  for (size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (c == ' ' || c == '\t') {
      if (in_word) {
        words.push_back(cur);
        first_quoted.push_back(quoted_start);
        cur.clear();
        in_word = false;
      }
      continue;
    }
    const bool word_start = !in_word;
    if (word_start) quoted_start = c == '\'' || c == '"';
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
  CheckInlinePrograms(words);
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
