// libFuzzer target: a benchmark method's command template (campaign/command_template.h). the
// input up to its first NUL byte is a template, split by SplitCommandTemplate; the NUL-separated
// rest are placeholder values (hostile defaults when absent), filled in by
// ExpandCommandTemplate. documented failures: penumbra::ConfigError from the split,
// penumbra::Error from the expansion for a placeholder it has no value for; any other
// exception, a crash, a sanitizer report, or an accepted template that breaks the rules is a
// finding:
//   - the argument vector has one argument per word, each the word with its placeholders
//     replaced by their values (checked against an independent substitution): no value is
//     split across arguments or merged into a neighbour;
//   - a word holding a placeholder holds nothing else but letters, digits and _ - . / , : + = @ %
//     and no two placeholders touch;
//   - when the program is a shell or python, no placeholder stands in its options or its
//     program text (the script of sh -c, the code of python -c, a script file);
//   - splitting is deterministic.
// docs/fuzzing.md.

#include <cstddef>
#include <cstdint>
#include <map>
#include <string>
#include <string_view>
#include <vector>

#include "penumbra/campaign/command_template.h"
#include "penumbra/core/error.h"

namespace {

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

bool Plain(char c) {
  return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
         std::string_view("_-./,:+=@%").find(c) != std::string_view::npos;
}

// the word with its placeholders filled, by its own walk; false for a placeholder without a
// value. a placeholder word must be plain around its placeholders, two may not touch
bool Reference(const std::string& w, const std::map<std::string, std::string>& values,
               std::string* out) {
  const bool placeholder_word = HasPlaceholder(w);
  size_t prev_end = std::string::npos;
  out->clear();
  for (size_t i = 0; i < w.size();) {
    if (w.compare(i, 2, "{{") == 0 || w.compare(i, 2, "}}") == 0) {
      if (placeholder_word) __builtin_trap();  // a literal brace beside a placeholder
      *out += w[i];
      i += 2;
      continue;
    }
    if (w[i] == '}') __builtin_trap();  // a lone brace was accepted
    if (w[i] == '{') {
      const size_t end = w.find('}', i);
      if (end == std::string::npos) __builtin_trap();
      if (prev_end == i) __builtin_trap();  // two placeholders merged
      const auto it = values.find(w.substr(i + 1, end - i - 1));
      if (it == values.end()) return false;
      *out += it->second;
      prev_end = end + 1;
      i = end + 1;
      continue;
    }
    if (placeholder_word && !Plain(w[i])) __builtin_trap();  // a value inside a longer text
    *out += w[i];
    ++i;
  }
  return true;
}

std::string Base(const std::string& w) {
  const size_t slash = w.rfind('/');
  return slash == std::string::npos ? w : w.substr(slash + 1);
}

// a shell or python as the program: its options and its program word hold no placeholder
void CheckProgram(const std::vector<std::string>& words) {
  const std::string base = Base(words[0]);
  const bool shell = base == "sh" || base == "bash" || base == "dash" || base == "zsh";
  const bool python = base == "python3" || base == "python";
  if (!shell && !python) return;
  size_t j = 1;
  bool stdin_script = false;  // sh -s: no operand is the script
  for (; j < words.size(); ++j) {
    const std::string& w = words[j];
    if (w == "--") {
      ++j;
      break;
    }
    if (w.size() < 2 || (w[0] != '-' && !(shell && w[0] == '+'))) break;
    if (HasPlaceholder(w)) __builtin_trap();
    if (python) {
      // long options take no argument but --check-hash-based-pycs MODE
      if (w[1] == '-') {
        if (w == "--check-hash-based-pycs") {
          if (j + 1 < words.size() && HasPlaceholder(words[j + 1])) __builtin_trap();
          ++j;
        }
        continue;
      }
      // -c CODE / -m MODULE / -W ARG / -X ARG, the argument attached or the next word; the
      // code and the module hold no placeholder either, and -c / -m end the options
      const size_t f = w.find_first_of("cmWX");
      if (f == std::string::npos) continue;
      const bool attached = f + 1 < w.size();
      if (!attached && j + 1 < words.size() && HasPlaceholder(words[j + 1])) __builtin_trap();
      if (w[f] == 'c' || w[f] == 'm') return;
      if (!attached) ++j;
      continue;
    }
    // a cluster's flags up to its first o / O, which takes the rest of the cluster or, at its
    // end, the next word as its argument (sh -so NAME: NAME is -o's, then operands follow)
    const size_t o = w[1] == '-' ? std::string::npos : w.find_first_of("oO", 1);
    const std::string flags = w.substr(1, o == std::string::npos ? std::string::npos : o - 1);
    if (w[0] == '-' && w[1] != '-' && flags.find('s') != std::string::npos) stdin_script = true;
    if (o != std::string::npos && o + 1 == w.size()) {
      if (j + 1 < words.size() && HasPlaceholder(words[j + 1])) __builtin_trap();
      ++j;
    }
  }
  if (stdin_script) return;
  // the script (sh -c SCRIPT, sh FILE, python FILE)
  if (j < words.size() && HasPlaceholder(words[j])) __builtin_trap();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string input(reinterpret_cast<const char*>(data), size);
  const size_t nul = input.find('\0');
  const std::string text = input.substr(0, nul);
  std::vector<std::string> given;
  if (nul != std::string::npos) {
    size_t pos = nul + 1;
    while (given.size() < 4) {
      const size_t end = input.find('\0', pos);
      given.push_back(input.substr(pos, end == std::string::npos ? std::string::npos : end - pos));
      if (end == std::string::npos) break;
      pos = end + 1;
    }
  }
  if (given.empty())
    given = {"/tmp/o $(touch X) `touch Y` ;x 'q\" {dataset}", "a b\tc\nd", "", "{{}}"};
  const std::vector<std::string> names = {"penumbra",   "dataset", "output", "workdir", "seed",
                                          "fx",         "fy",      "cx",     "cy",      "endpoint",
                                          "pythonpath", "goal_x",  "goal_y", "out_dir"};
  std::map<std::string, std::string> values;
  for (size_t k = 0; k < names.size(); ++k)
    values[names[k]] = given[k % given.size()] + (k % 2 ? " " + names[k] : "");

  std::vector<std::string> words;
  try {
    words = penumbra::SplitCommandTemplate(text);
  } catch (const penumbra::ConfigError&) {
    return 0;
  }
  if (words.empty()) __builtin_trap();
  if (penumbra::SplitCommandTemplate(text) != words) __builtin_trap();
  CheckProgram(words);

  std::vector<std::string> expected(words.size());
  bool known = true;
  for (size_t k = 0; k < words.size(); ++k)
    known = Reference(words[k], values, &expected[k]) && known;
  try {
    const std::vector<std::string> argv = penumbra::ExpandCommandTemplate(words, values);
    if (!known || argv != expected) __builtin_trap();
  } catch (const penumbra::Error&) {
    if (known) __builtin_trap();
  }
  return 0;
}
