#include "penumbra/core/text_match.h"

#include <charconv>
#include <cmath>

#include "penumbra/core/error.h"

namespace penumbra {

bool GlobMatch(std::string_view p, std::string_view t) {
  // iterative matcher with backtracking to the last '*'
  size_t pi = 0, ti = 0, star = std::string_view::npos, mark = 0;
  while (ti < t.size()) {
    if (pi < p.size() && (p[pi] == '?' || p[pi] == t[ti])) {
      ++pi;
      ++ti;
    } else if (pi < p.size() && p[pi] == '*') {
      star = pi++;
      mark = ti;
    } else if (star != std::string_view::npos) {
      pi = star + 1;
      ti = ++mark;
    } else {
      return false;
    }
  }
  while (pi < p.size() && p[pi] == '*') ++pi;
  return pi == p.size();
}

std::optional<double> ParseDecimal(std::string_view s) {
  // the grammar first: from_chars alone would take "inf", "nan" and hex digits
  std::string_view body = s;
  if (!body.empty() && (body.front() == '+' || body.front() == '-')) body.remove_prefix(1);
  size_t i = 0, digits = 0;
  while (i < body.size() && body[i] >= '0' && body[i] <= '9') ++i, ++digits;
  if (i < body.size() && body[i] == '.') {
    ++i;
    while (i < body.size() && body[i] >= '0' && body[i] <= '9') ++i, ++digits;
  }
  if (digits == 0) return std::nullopt;
  if (i < body.size() && (body[i] == 'e' || body[i] == 'E')) {
    ++i;
    if (i < body.size() && (body[i] == '+' || body[i] == '-')) ++i;
    const size_t exp_start = i;
    while (i < body.size() && body[i] >= '0' && body[i] <= '9') ++i;
    if (i == exp_start) return std::nullopt;
  }
  if (i != body.size()) return std::nullopt;
  if (!s.empty() && s.front() == '+') s.remove_prefix(1);
  double v = 0;
  const auto r = std::from_chars(s.data(), s.data() + s.size(), v);
  if (r.ec != std::errc() || r.ptr != s.data() + s.size() || !std::isfinite(v)) return std::nullopt;
  return v;
}

std::string Excerpt(std::string_view text, size_t max_bytes) {
  if (text.size() <= max_bytes) return SanitizeForMessage(text, 4 * max_bytes + 16);
  // cut at a character boundary
  size_t n = max_bytes;
  while (n > 0 && (static_cast<unsigned char>(text[n]) & 0xC0) == 0x80) --n;
  return SanitizeForMessage(text.substr(0, n), 4 * max_bytes + 16) + "...";
}

std::optional<std::string> NameLengthProblem(std::string_view name) {
  if (name.size() <= kMaxNameLength) return std::nullopt;
  return "a name of " + std::to_string(name.size()) + " characters ('" + Excerpt(name, 16) +
         "'); expected at most " + std::to_string(kMaxNameLength) + " characters";
}

}  // namespace penumbra
