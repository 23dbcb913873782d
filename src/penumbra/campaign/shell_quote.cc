#include "penumbra/campaign/shell_quote.h"

#include "penumbra/core/error.h"

namespace penumbra {
namespace {

bool PlainWordChar(char c) {
  return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
         std::string_view("_-./,:+=@%").find(c) != std::string_view::npos;
}

}  // namespace

std::string ShellQuote(std::string_view s) {
  std::string out = "'";
  for (char c : s) {
    if (c == '\0') throw Error("cannot quote a value holding a NUL byte for a shell");
    if (c == '\'')
      out += "'\\''";
    else
      out += c;
  }
  return out + "'";
}

std::string ShellCommandLine(const std::vector<std::string>& argv) {
  std::string out;
  for (size_t i = 0; i < argv.size(); ++i) {
    const std::string& w = argv[i];
    bool plain = !w.empty();
    for (char c : w) plain = plain && PlainWordChar(c);
    if (i == 0 && w.find('=') != std::string::npos) plain = false;
    if (i > 0) out += ' ';
    out += plain ? w : ShellQuote(w);
  }
  return out;
}

std::optional<size_t> FindControlCharacter(std::string_view s) {
  for (size_t i = 0; i < s.size(); ++i) {
    const unsigned char c = static_cast<unsigned char>(s[i]);
    if (c < 0x20 || c == 0x7f) return i;
  }
  return std::nullopt;
}

}  // namespace penumbra
