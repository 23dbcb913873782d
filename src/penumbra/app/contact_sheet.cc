#include "penumbra/app/contact_sheet.h"

#include <fmt/format.h>

#include <array>
#include <filesystem>

#include "penumbra/bench/preset_scene.h"
#include "penumbra/output/png_io.h"
#include "penumbra/world/default_world.h"

namespace penumbra {
namespace {

// 5 x 7 glyphs of the letters of the bundled preset names (rows top down, 5 bits each);
// other characters are drawn as a block
int Glyph(char c, int row) {
  static const std::array<std::pair<char, std::array<int, 7>>, 8> kGlyphs = {{
      {'a', {0b00000, 0b00000, 0b01110, 0b00001, 0b01111, 0b10001, 0b01111}},
      {'e', {0b00000, 0b00000, 0b01110, 0b10001, 0b11111, 0b10000, 0b01110}},
      {'i', {0b00100, 0b00000, 0b01100, 0b00100, 0b00100, 0b00100, 0b01110}},
      {'j', {0b00010, 0b00000, 0b00110, 0b00010, 0b00010, 0b10010, 0b01100}},
      {'m', {0b00000, 0b00000, 0b11010, 0b10101, 0b10101, 0b10001, 0b10001}},
      {'n', {0b00000, 0b00000, 0b10110, 0b11001, 0b10001, 0b10001, 0b10001}},
      {'o', {0b00000, 0b00000, 0b01110, 0b10001, 0b10001, 0b10001, 0b01110}},
      {'r', {0b00000, 0b00000, 0b10110, 0b11001, 0b10000, 0b10000, 0b10000}},
  }};
  for (const auto& [ch, rows] : kGlyphs)
    if (ch == c) return rows[row];
  return c == ' ' ? 0 : 0b11111;
}

void DrawText(ImageU8* img, int x0, int y0, const std::string& text, int scale) {
  for (size_t k = 0; k < text.size(); ++k)
    for (int row = 0; row < 7; ++row)
      for (int col = 0; col < 5; ++col) {
        if (!(Glyph(text[k], row) >> (4 - col) & 1)) continue;
        for (int dy = 0; dy < scale; ++dy)
          for (int dx = 0; dx < scale; ++dx) {
            const int x = x0 + (static_cast<int>(k) * 6 + col) * scale + dx;
            const int y = y0 + row * scale + dy;
            if (x < 0 || y < 0 || x >= img->width || y >= img->height) continue;
            uint8_t* p = img->at(x, y);
            p[0] = p[1] = p[2] = 20;
          }
      }
}

}  // namespace

int MakeContactSheet(const ContactSheetOptions& o) {
  const std::vector<std::string> worlds =
      o.worlds.empty() ? std::vector<std::string>{DefaultWorldPath()} : o.worlds;
  constexpr int kGap = 8, kBar = 28;
  const int n = static_cast<int>(o.presets.size());
  const int rows = static_cast<int>(worlds.size()), row_h = o.height + kBar;
  ImageU8 sheet(n * o.width + (n - 1) * kGap, rows * row_h + (rows - 1) * kGap, 3, 255);
  for (int r = 0; r < rows; ++r) {
    WorldConfig world = LoadWorldFile(worlds[r]);
    world.render.threads = o.threads;
    if (o.backend) world.render.backend = *o.backend;
    const int y0 = r * (row_h + kGap);
    for (int i = 0; i < n; ++i) {
      PresetScene p = LoadPresetScene(world, o.presets[i]);
      p.StepTo(o.time_sec);
      const RenderedFrame f = p.Render(0, o.width, o.height);
      const int x0 = i * (o.width + kGap);
      for (int y = 0; y < o.height; ++y)
        for (int x = 0; x < o.width; ++x)
          for (int c = 0; c < 3; ++c) sheet.at(x0 + x, y0 + kBar + y)[c] = f.rgb.at(x, y)[c];
      const std::string label = o.presets[i];
      DrawText(&sheet, x0 + (o.width - static_cast<int>(label.size()) * 18) / 2, y0 + 3, label, 3);
      fmt::print("{} {}: t = {:.3f} s, {} effects, {} agents\n", worlds[r], label,
                 p.session->sim().time(), p.session->effects().effects().size(),
                 p.session->effects().agents().size());
    }
  }
  const std::filesystem::path out(o.out);
  if (out.has_parent_path()) std::filesystem::create_directories(out.parent_path());
  WritePngRgb8(o.out, sheet);
  fmt::print("wrote {} ({} x {})\n", o.out, sheet.width, sheet.height);
  return 0;
}

}  // namespace penumbra
