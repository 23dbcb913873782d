#include "penumbra/app/compare_command.h"

#include <fmt/format.h>

#include <CLI/CLI.hpp>
#include <cstdio>
#include <filesystem>
#include <string>
#include <system_error>

#include "penumbra/app/cli_options.h"
#include "penumbra/core/error.h"
#include "penumbra/core/image.h"
#include "penumbra/core/image_file_limits.h"
#include "penumbra/eval/flip.h"
#include "penumbra/output/png_io.h"

namespace penumbra {
namespace {

namespace fs = std::filesystem;

constexpr const char* kExpectedPng = "expected an 8-bit sRGB PNG (RGB or grey, no alpha)";

// `path` as an (H x W x 3) uint8 sRGB image; its declared size is checked against the image file
// caps (core/image_file_limits.h) before anything is decoded
// @throws ConfigError naming `path`: missing, not a PNG, too large, 16-bit or with alpha
ImageU8 ReadComparePng(const std::string& path) {
  std::error_code ec;
  if (!fs::exists(path, ec))
    throw ConfigError(path, 0, "", std::string("no such file; ") + kExpectedPng);
  CheckImageFileSize(path);
  PngImage png;
  try {
    png = ReadPng(path);
  } catch (const ConfigError&) {
    throw;
  } catch (const Error& e) {
    throw ConfigError(path, 0, "", std::string(e.what()) + "; " + kExpectedPng);
  }
  if (png.bit_depth != 8 || (png.channels != 1 && png.channels != 3))
    throw ConfigError(
        path, 0, "",
        fmt::format("a {}-bit PNG with {} channel(s){}; {}", png.bit_depth, png.channels,
                    png.channels == 2 || png.channels == 4 ? " (alpha)" : "", kExpectedPng));
  ImageU8 image(png.width, png.height, 3);
  const size_t pixels = static_cast<size_t>(png.width) * png.height;
  for (size_t p = 0; p < pixels; ++p)
    for (int c = 0; c < 3; ++c)
      image.data[3 * p + c] = static_cast<uint8_t>(png.samples[png.channels == 1 ? p : 3 * p + c]);
  return image;
}

class CompareCommand : public Command {
 public:
  std::string name() const override { return "compare"; }
  std::string summary() const override {
    return "LDR-FLIP difference of a test PNG from a reference PNG (mean, weighted quartiles; "
           "--heatmap PNG)";
  }

  void AddOptions(CLI::App* verb) override {
    verb->add_option("reference", reference_, "reference image (8-bit sRGB PNG)")->required();
    verb->add_option("test", test_, "test image (8-bit sRGB PNG, the reference's size)")
        ->required();
    verb->add_option("--heatmap", heatmap_,
                     "write the per-pixel FLIP error as a PNG coloured with the magma map");
    AddDecimal(
        verb, "--ppd", [this](double v) { ppd_ = v; }, 0, true,
        fmt::format("pixels per degree of visual angle, at most {:g} (default {:.4f}: a 0.7 m "
                    "wide 3840-pixel monitor seen from 0.7 m)",
                    kFlipMaxPixelsPerDegree, kFlipDefaultPixelsPerDegree));
  }

  int Run(const CommandArgs&) override {
    if (ppd_ > kFlipMaxPixelsPerDegree)
      throw ConfigError("", 0, "--ppd",
                        fmt::format("{:g} is out of range; expected a number in (0, {:g}]", ppd_,
                                    kFlipMaxPixelsPerDegree));
    const ImageU8 reference = ReadComparePng(reference_);
    const ImageU8 test = ReadComparePng(test_);
    if (reference.width != test.width || reference.height != test.height)
      throw ConfigError(
          test_, 0, "",
          fmt::format("{} x {} pixels; expected the size of the reference {} "
                      "({} x {})",
                      test.width, test.height, reference_, reference.width, reference.height));
    const ImageF error = FlipErrorMap(reference, test, ppd_);
    const FlipStats s = PoolFlipErrors(error);
    std::printf(
        "LDR-FLIP between reference image <%s> and test image <%s> (%d x %d, %.4f pixels per "
        "degree)\n"
        "     Mean: %.6f\n"
        "     Weighted median: %.6f\n"
        "     1st weighted quartile: %.6f\n"
        "     3rd weighted quartile: %.6f\n"
        "     Min: %.6f\n"
        "     Max: %.6f\n",
        reference_.c_str(), test_.c_str(), reference.width, reference.height, ppd_, s.mean,
        s.weighted_median, s.weighted_q1, s.weighted_q3, s.min, s.max);
    if (!heatmap_.empty()) {
      WritePngRgb8(heatmap_, FlipMagmaHeatmap(error));
      std::printf("     Heatmap: %s\n", heatmap_.c_str());
    }
    std::fflush(stdout);
    return 0;
  }

 private:
  std::string reference_, test_, heatmap_;
  double ppd_ = kFlipDefaultPixelsPerDegree;
};

}  // namespace

std::unique_ptr<Command> MakeCompareCommand() { return std::make_unique<CompareCommand>(); }

}  // namespace penumbra
