#include "penumbra/campaign/benchmark_text.h"

#include <fmt/format.h>

#include <cmath>
#include <fstream>
#include <sstream>

#include "penumbra/core/error.h"
#include "penumbra/world/yaml_reader.h"

namespace penumbra::benchmark_text {

double Since(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

std::string ReadText(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

void WriteText(const std::filesystem::path& p, const std::string& text) {
  const std::filesystem::path tmp = p.string() + ".tmp";
  std::error_code ec;
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    out << text;
    if (!out.flush()) {
      std::filesystem::remove(tmp, ec);
      throw Error("cannot write " + p.string());
    }
  }
  std::filesystem::rename(tmp, p, ec);
  if (ec) {
    std::filesystem::remove(tmp, ec);
    throw Error("cannot write " + p.string() + ": " + ec.message());
  }
}

std::string Field(double v) { return std::isfinite(v) ? FormatNumber(v) : ""; }

std::string CsvQuote(const std::string& s) {
  if (s.find_first_of(",\"\n") == std::string::npos) return s;
  std::string out = "\"";
  for (char c : s) out += c == '"' ? std::string("\"\"") : std::string(1, c == '\n' ? ' ' : c);
  return out + "\"";
}

SummaryCell Cell(const std::vector<double>& v) {
  SummaryCell c;
  c.n = static_cast<int>(v.size());
  if (v.empty()) return c;
  double sum = 0;
  for (double x : v) sum += x;
  c.mean = sum / c.n;
  double ss = 0;
  for (double x : v) ss += (x - c.mean) * (x - c.mean);
  c.std = c.n > 1 ? std::sqrt(ss / (c.n - 1)) : 0.0;
  return c;
}

std::string Pm(const SummaryCell& c, int digits) {
  if (c.n == 0) return "-";
  return fmt::format("{:.{}f} ± {:.{}f}", c.mean, digits, c.std, digits);
}

}  // namespace penumbra::benchmark_text
