#pragma once
// small text and statistics helpers shared by the benchmark's jobs, runner and reports
// (SLAM and navigation): whole-file reads and writes, CSV fields, mean +- std cells.

#include <chrono>
#include <filesystem>
#include <string>
#include <vector>

#include "penumbra/campaign/benchmark_report.h"

namespace penumbra::benchmark_text {

/// wall seconds since `t` (steady clock).
double Since(std::chrono::steady_clock::time_point t);
/// the whole file as bytes; "" when it cannot be read.
std::string ReadText(const std::filesystem::path& p);
/// replaces the file with `text` atomically: written to `<p>.tmp` and renamed over `p`, so
/// an interruption leaves the old file or the new one, never half of one.
/// @throws Error when it cannot be written (the .tmp file is removed).
void WriteText(const std::filesystem::path& p, const std::string& text);
/// a CSV field: `v` as FormatNumber writes it, "" for NaN / infinity.
std::string Field(double v);
/// `s` quoted for CSV (RFC 4180) when it holds a comma, quote or newline (newlines become
/// spaces).
std::string CsvQuote(const std::string& s);
/// n, mean and sample standard deviation (n - 1; 0 for one value) of `v`.
SummaryCell Cell(const std::vector<double>& v);
/// "mean ± std" with `digits` decimals, "-" for an empty cell.
std::string Pm(const SummaryCell& c, int digits);

}  // namespace penumbra::benchmark_text
