#include "penumbra/core/error.h"

#include <algorithm>
#include <cstdint>
#include <utility>
#include <vector>

namespace penumbra {
namespace {

// length of the valid UTF-8 sequence of 2-4 bytes starting at s[i], 0 if there is none
// (RFC 3629: no overlong forms, no surrogates, nothing above U+10FFFF).
size_t Utf8SequenceLength(std::string_view s, size_t i) {
  const auto b = [&](size_t k) { return static_cast<uint8_t>(s[k]); };
  const uint8_t c = b(i);
  size_t n = 0;
  uint8_t lo = 0x80, hi = 0xBF;
  if (c >= 0xC2 && c <= 0xDF) {
    n = 2;
  } else if (c >= 0xE0 && c <= 0xEF) {
    n = 3;
    if (c == 0xE0) lo = 0xA0;
    if (c == 0xED) hi = 0x9F;
  } else if (c >= 0xF0 && c <= 0xF4) {
    n = 4;
    if (c == 0xF0) lo = 0x90;
    if (c == 0xF4) hi = 0x8F;
  } else {
    return 0;
  }
  if (i + n > s.size()) return 0;
  if (b(i + 1) < lo || b(i + 1) > hi) return 0;
  for (size_t k = 2; k < n; ++k) {
    if (b(i + k) < 0x80 || b(i + k) > 0xBF) return 0;
  }
  return n;
}

// appends the printable form of the byte or UTF-8 sequence at text[i]; returns its length.
size_t EscapeOne(std::string_view text, size_t i, std::string* out) {
  static constexpr char kHex[] = "0123456789abcdef";
  const auto c = static_cast<uint8_t>(text[i]);
  if (c >= 0x20 && c < 0x7F) {
    *out += static_cast<char>(c);
    return 1;
  }
  if (const size_t n = c >= 0x80 ? Utf8SequenceLength(text, i) : 0; n > 0) {
    out->append(text.substr(i, n));
    return n;
  }
  *out += "\\x";
  *out += kHex[c >> 4];
  *out += kHex[c & 15];
  return 1;
}

}  // namespace

std::string SanitizeForMessage(std::string_view text, size_t max_bytes) {
  std::string out;
  size_t i = 0;
  while (i < text.size() && out.size() < max_bytes) i += EscapeOne(text, i, &out);
  if (i == text.size() && out.size() <= max_bytes) return out;
  // too long: the first three quarters and the last quarter of the budget, in input bytes
  out.clear();
  i = 0;
  const size_t head_budget = max_bytes * 3 / 4;
  while (i < text.size() && out.size() < head_budget) i += EscapeOne(text, i, &out);
  // the tail: whole characters from the end while their printable form fits a quarter
  size_t j = text.size() - std::min(text.size() - i, max_bytes / 4);
  while (j < text.size() && (static_cast<uint8_t>(text[j]) & 0xC0) == 0x80) ++j;
  std::vector<std::pair<size_t, std::string>> pieces;  // (input bytes, printable form)
  size_t tail_size = 0;
  for (size_t k = j; k < text.size();) {
    std::string piece;
    const size_t n = EscapeOne(text, k, &piece);
    tail_size += piece.size();
    pieces.emplace_back(n, std::move(piece));
    k += n;
  }
  size_t first = 0;
  for (; first < pieces.size() && tail_size > max_bytes / 4; ++first) {
    tail_size -= pieces[first].second.size();
    j += pieces[first].first;
  }
  std::string tail;
  for (size_t p = first; p < pieces.size(); ++p) tail += pieces[p].second;
  return out + " ... [" + std::to_string(j - i) + " bytes elided] ... " + tail;
}

std::string ConfigError::Format(const std::string& file, int line, const std::string& key,
                                const std::string& problem) {
  std::string s = file.empty() ? std::string("<command line>") : SanitizeForMessage(file);
  if (line > 0) s += ':' + std::to_string(line);
  if (!key.empty()) s += ": " + SanitizeForMessage(key, 256);
  s += ": " + SanitizeForMessage(problem, 1024);
  return s;
}

}  // namespace penumbra
