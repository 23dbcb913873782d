#include "penumbra/assets/procedural_material.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <optional>
#include <vector>

#include "penumbra/core/cache_dir.h"
#include "penumbra/core/error.h"
#include "penumbra/core/input_file.h"
#include "penumbra/core/output_file.h"
#include "penumbra/core/thread_pool.h"

namespace penumbra {
namespace {

constexpr float kPi = 3.14159265358979f;

uint64_t Mix64(uint64_t z) {  // splitmix64's finaliser
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
  return z ^ (z >> 31);
}

// a uniform value in [0, 1) for (seed, a, b, salt).
float Hash01(uint64_t seed, int64_t a, int64_t b, uint64_t salt) {
  uint64_t h = Mix64(seed ^ 0x9e3779b97f4a7c15ull);
  h = Mix64(h ^ static_cast<uint64_t>(a) * 0xd6e8feb86659fd93ull);
  h = Mix64(h ^ static_cast<uint64_t>(b) * 0xa0761d6478bd642full);
  h = Mix64(h ^ salt);
  return static_cast<float>(h >> 40) * (1.0f / 16777216.0f);
}

int Wrap(int i, int n) {
  i %= n;
  return i < 0 ? i + n : i;
}

float Smooth(float t) { return t * t * (3 - 2 * t); }

// periodic value noise in [0, 1] at (u, v) in images, with cu x cv cells per image.
float ValueNoise(uint64_t seed, uint64_t salt, float u, float v, int cu, int cv) {
  const float x = u * cu, y = v * cv;
  const float fx = std::floor(x), fy = std::floor(y);
  const int ix = static_cast<int>(fx), iy = static_cast<int>(fy);
  const float tx = Smooth(x - fx), ty = Smooth(y - fy);
  auto at = [&](int i, int j) { return Hash01(seed, Wrap(i, cu), Wrap(j, cv), salt); };
  const float a = at(ix, iy), b = at(ix + 1, iy), c = at(ix, iy + 1), d = at(ix + 1, iy + 1);
  return (a + (b - a) * tx) + ((c + (d - c) * tx) - (a + (b - a) * tx)) * ty;
}

// fractal sum of `octaves` periodic noises, the first with cu x cv cells, each further one
// with twice the cells and half the amplitude; in [0, 1].
float Fbm(uint64_t seed, uint64_t salt, float u, float v, int cu, int cv, int octaves) {
  float sum = 0, amp = 1, norm = 0;
  for (int o = 0; o < octaves; ++o) {
    sum += amp * ValueNoise(seed, salt + 7919u * o, u, v, cu << o, cv << o);
    norm += amp;
    amp *= 0.5f;
  }
  return sum / norm;
}

// one texel of a material: linear albedo, roughness, metallic, height (m).
struct Texel {
  Eigen::Vector3f albedo{0.5f, 0.5f, 0.5f};
  float roughness = 0.5f;
  float metallic = 0;
  float height_m = 0;
};

// every type below: texel at image coordinates (u, v) in [0, 1), image side `size` m.
struct Generator {
  uint64_t seed;
  float size;
  Eigen::Vector3f tint;  // config colour (or the type's default)

  // distance (m) from (x, y) to the nearest multiple of `pitch` (grid lines).
  static float LineDistance(float x, float pitch) {
    const float r = x - pitch * std::round(x / pitch);
    return std::abs(r);
  }
  // 0 in a groove of half-width w (m), 1 beyond w + bevel, smooth between.
  static float Groove(float d, float w, float bevel) {
    return Smooth(std::clamp((d - w) / bevel, 0.0f, 1.0f));
  }

  Texel Wood(float u, float v) const {
    Texel t;
    const float plank_w = 0.15f, plank_l = 1.2f;
    const int rows = std::max(1, static_cast<int>(std::lround(size / plank_w)));
    const float pw = size / rows;  // plank width that tiles
    const float x = u * size, y = v * size;
    const int row = std::min(rows - 1, static_cast<int>(y / pw));
    const int per_row = std::max(1, static_cast<int>(std::lround(size / plank_l)));
    const float pl = size / per_row;
    const float offset = Hash01(seed, row, 0, 11) * pl;  // staggered joints
    const float xs = x + offset;
    const int seg = static_cast<int>(std::floor(xs / pl));
    const int plank = row * 4096 + Wrap(seg, per_row);
    // plank tone and grain: streaks stretched along the plank (x), rings across it
    const float tone = Hash01(seed, plank, 1, 12);
    const float streak = Fbm(seed, 13 + plank, u, v, per_row * 3, rows * 24, 4);
    const float rings =
        0.5f + 0.5f * std::sin(2 * kPi *
                               (y / pw * 3.0f + 4.0f * streak + Hash01(seed, plank, 2, 14) * 10));
    const float fine = Fbm(seed, 15, u, v, 64, rows * 64, 2);
    const Eigen::Vector3f dark = Eigen::Vector3f(0.20f, 0.095f, 0.038f).cwiseProduct(tint);
    const Eigen::Vector3f light = Eigen::Vector3f(0.46f, 0.26f, 0.12f).cwiseProduct(tint);
    float k = 0.35f + 0.35f * tone + 0.2f * rings * streak + 0.1f * fine;
    t.albedo = dark + (light - dark) * std::clamp(k, 0.0f, 1.0f);
    t.roughness = 0.45f + 0.15f * streak + 0.05f * tone;
    // 1 mm joints between planks, 1 mm deep with a 1.5 mm bevel
    const float dy = std::min(y - row * pw, (row + 1) * pw - y);
    const float dx = LineDistance(xs, pl);
    const float g = Groove(std::min(dx, dy), 0.0005f, 0.0015f);
    // brushed grain: 0.2 mm across the rings, 0.1 mm of fine fibre
    t.height_m = -0.001f * (1 - g) + (0.0002f * rings + 0.0001f * fine) * g;
    t.albedo *= 0.35f + 0.65f * g;
    t.roughness = t.roughness * g + 0.9f * (1 - g);
    return t;
  }

  Texel Tiles(float u, float v) const {
    Texel t;
    const int n = std::max(1, static_cast<int>(std::lround(size / 0.3f)));
    const float tile = size / n;
    const float x = u * size, y = v * size;
    const int i = std::min(n - 1, static_cast<int>(x / tile)),
              j = std::min(n - 1, static_cast<int>(y / tile));
    const float d = std::min(LineDistance(x, tile), LineDistance(y, tile));
    const float g = Groove(d, 0.002f, 0.0015f);  // 4 mm grout, 2 mm deep
    const float shade = 0.93f + 0.14f * Hash01(seed, i, j, 21);
    const float speckle = Fbm(seed, 22, u, v, n * 64, n * 64, 2);
    const Eigen::Vector3f tile_c = tint * (shade * (0.96f + 0.08f * speckle));
    const Eigen::Vector3f grout =
        Eigen::Vector3f(0.28f, 0.27f, 0.25f) * (0.9f + 0.2f * Fbm(seed, 23, u, v, 256, 256, 2));
    t.albedo = grout + (tile_c - grout) * g;
    t.roughness = (0.12f + 0.08f * Fbm(seed, 24, u, v, 8 * n, 8 * n, 3)) * g + 0.85f * (1 - g);
    // lippage: each tile tilted by up to 0.3 mm over its width
    const float sx = (Hash01(seed, i, j, 25) - 0.5f) * 0.0006f / tile;
    const float sy = (Hash01(seed, i, j, 26) - 0.5f) * 0.0006f / tile;
    const float lx = x - (i + 0.5f) * tile, ly = y - (j + 0.5f) * tile;
    t.height_m = (sx * lx + sy * ly) * g - 0.002f * (1 - g);
    return t;
  }

  // pores: cells of `cell` m, each holding one pore with probability p, radius r0 ... r1.
  float Pore(float x, float y, float cell, float p, float r0, float r1, uint64_t salt) const {
    const int cells = std::max(1, static_cast<int>(std::lround(size / cell)));
    const float c = size / cells;
    const int ci = static_cast<int>(std::floor(x / c)), cj = static_cast<int>(std::floor(y / c));
    float depth = 0;
    for (int dj = -1; dj <= 1; ++dj)
      for (int di = -1; di <= 1; ++di) {
        const int i = Wrap(ci + di, cells), j = Wrap(cj + dj, cells);
        if (Hash01(seed, i, j, salt) >= p) continue;
        const float px = (ci + di + Hash01(seed, i, j, salt + 1)) * c;
        const float py = (cj + dj + Hash01(seed, i, j, salt + 2)) * c;
        const float r = r0 + (r1 - r0) * Hash01(seed, i, j, salt + 3);
        const float d = std::hypot(x - px, y - py);
        if (d < r) depth = std::max(depth, 1 - (d / r) * (d / r));
      }
    return depth;  // 0 outside, 1 at a pore's centre
  }

  Texel Concrete(float u, float v) const {
    Texel t;
    const float x = u * size, y = v * size;
    const int blotch = std::max(1, static_cast<int>(std::lround(size / 0.3f)));
    const float b = Fbm(seed, 31, u, v, blotch, blotch, 3);
    const float grain = Fbm(seed, 32, u, v, blotch * 32, blotch * 32, 3);
    const float pore = Pore(x, y, 0.006f, 0.25f, 0.0006f, 0.002f, 33);
    const float k = 0.75f + 0.3f * b + 0.15f * grain;
    t.albedo = tint * k * (1 - 0.5f * pore);
    t.roughness = 0.82f + 0.12f * grain;
    t.height_m = 0.0003f * grain - 0.0015f * pore;
    return t;
  }

  Texel Plaster(float u, float v) const {
    Texel t;
    // trowel undulation: 1 mm over ~0.1 m
    const int trowel = std::max(1, static_cast<int>(std::lround(size / 0.1f)));
    const float w = Fbm(seed, 41, u, v, trowel, trowel, 3);
    // sand finish: 0.2 mm grains of ~4 mm
    const int gcells = std::max(4, static_cast<int>(std::lround(size / 0.004f)));
    const float grain = Fbm(seed, 42, u, v, gcells, gcells, 2);
    t.albedo = tint * (0.92f + 0.1f * w + 0.05f * grain);
    t.roughness = 0.88f + 0.08f * grain;
    t.height_m = 0.001f * w + 0.0002f * grain;
    return t;
  }

  Texel PaintedMetal(float u, float v) const {
    Texel t;
    const float x = u * size, y = v * size;
    const int peel = std::max(4, static_cast<int>(std::lround(size / 0.004f)));
    const float p = Fbm(seed, 51, u, v, peel, peel, 2);
    const int dirt_c = std::max(1, static_cast<int>(std::lround(size / 0.25f)));
    const float dirt = Fbm(seed, 52, u, v, dirt_c, dirt_c, 4);
    t.albedo = tint * (0.85f + 0.25f * dirt);
    t.roughness = 0.32f + 0.12f * dirt + 0.04f * p;
    // orange peel (60 um over 4 mm) and dings of the sheet (0.5 mm over ~3 cm)
    const int ding_c = std::max(1, static_cast<int>(std::lround(size / 0.03f)));
    const float ding = Fbm(seed, 54, u, v, ding_c, ding_c, 2);
    t.height_m = 0.00006f * p + 0.0005f * ding;
    // scratches: segments 2-20 cm long, 0.3-1 mm wide, bare steel in them
    const int n = std::max(1, static_cast<int>(std::lround(40 * size * size)));
    for (int k = 0; k < n; ++k) {
      const float cx = Hash01(seed, k, 0, 53) * size, cy = Hash01(seed, k, 1, 53) * size;
      const float ang = Hash01(seed, k, 2, 53) * kPi;
      const float len = 0.02f + 0.18f * Hash01(seed, k, 3, 53);
      const float wid = 0.00015f + 0.00035f * Hash01(seed, k, 4, 53);
      const float ex = std::cos(ang), ey = std::sin(ang);
      for (int oy = -1; oy <= 1; ++oy)
        for (int ox = -1; ox <= 1; ++ox) {
          const float dx = x + ox * size - cx, dy = y + oy * size - cy;
          const float along = dx * ex + dy * ey, across = -dx * ey + dy * ex;
          if (std::abs(along) > 0.5f * len || std::abs(across) > wid) continue;
          t.albedo = Eigen::Vector3f(0.56f, 0.57f, 0.58f);
          t.metallic = 1;
          t.roughness = 0.3f;
          t.height_m = -0.00005f;
        }
    }
    return t;
  }

  Texel Cardboard(float u, float v) const {
    Texel t;
    const float y = v * size;
    const int flutes = std::max(1, static_cast<int>(std::lround(size / 0.008f)));
    const float pitch = size / flutes;
    const float f = 0.5f + 0.5f * std::cos(2 * kPi * y / pitch);
    const int fc = std::max(8, static_cast<int>(std::lround(size / 0.002f)));
    const float fibre = Fbm(seed, 61, u, v, fc / 8, fc, 2);
    const int bc = std::max(1, static_cast<int>(std::lround(size / 0.1f)));
    const float blotch = Fbm(seed, 62, u, v, bc, bc, 3);
    t.albedo = tint * (0.88f + 0.12f * fibre + 0.1f * blotch - 0.03f * f);
    t.roughness = 0.86f + 0.08f * fibre;
    t.height_m = 0.00015f * f + 0.00002f * fibre;
    return t;
  }

  Texel Fabric(float u, float v) const {
    Texel t;
    const int threads = std::max(2, 2 * static_cast<int>(std::lround(size / 0.002f)));
    const float x = u * threads, y = v * threads;
    const int i = static_cast<int>(std::floor(x)), j = static_cast<int>(std::floor(y));
    const float fx = x - i, fy = y - j;
    // plain weave: the warp (along v) is on top where i + j is even, the weft elsewhere
    const bool warp_up = ((i + j) & 1) == 0;
    const float profile = warp_up ? std::sin(kPi * fx) : std::sin(kPi * fy);
    const float thread_tone = Hash01(seed, warp_up ? i : 100000 + j, 0, 71);
    const float fibre = Fbm(seed, 72, u, v, threads * 2, threads * 2, 1);
    t.albedo = tint * (0.8f + 0.15f * thread_tone + 0.1f * fibre) * (0.75f + 0.25f * profile);
    t.roughness = 0.92f + 0.06f * fibre;
    t.height_m = 0.0002f * profile;
    return t;
  }
};

Eigen::Vector3f DefaultColour(const std::string& type) {
  if (type == "tiles") return {0.78f, 0.76f, 0.71f};
  if (type == "concrete") return {0.30f, 0.30f, 0.29f};
  if (type == "plaster") return {0.80f, 0.78f, 0.74f};
  if (type == "painted_metal") return {0.06f, 0.16f, 0.32f};
  if (type == "cardboard") return {0.45f, 0.27f, 0.12f};
  if (type == "fabric") return {0.12f, 0.20f, 0.40f};
  return {1, 1, 1};  // wood: its own palette, untinted
}

std::shared_ptr<const TextureImage> MakeImage(int n, std::vector<uint8_t> bytes) {
  return std::make_shared<const TextureImage>(n, n, 1, std::move(bytes));
}

}  // namespace

double ProceduralDefaultSize(const std::string& type) {
  if (type == "wood") return 1.2;
  if (type == "tiles") return 0.6;
  if (type == "concrete" || type == "plaster" || type == "painted_metal") return 1.0;
  if (type == "cardboard") return 0.5;
  if (type == "fabric") return 0.2;
  throw Error("unknown procedural material type '" + type + "'");
}

namespace {

// the image side of `config`, m: its size_m, else the type's default.
double ImageSide(const ProceduralMaterialConfig& config) {
  return config.size_m > 0 ? config.size_m : ProceduralDefaultSize(config.type);
}

}  // namespace

ProceduralMaps GenerateProceduralMaterial(const ProceduralMaterialConfig& config) {
  ProceduralMaps out;
  out.size_m = ImageSide(config);
  const int n = config.resolution;
  Generator gen{config.seed, static_cast<float>(out.size_m),
                config.color ? *config.color : DefaultColour(config.type)};
  Texel (Generator::*fn)(float, float) const = nullptr;
  const std::string& t = config.type;
  fn = t == "wood"            ? &Generator::Wood
       : t == "tiles"         ? &Generator::Tiles
       : t == "concrete"      ? &Generator::Concrete
       : t == "plaster"       ? &Generator::Plaster
       : t == "painted_metal" ? &Generator::PaintedMetal
       : t == "cardboard"     ? &Generator::Cardboard
       : t == "fabric"        ? &Generator::Fabric
                              : nullptr;
  if (fn == nullptr) throw Error("unknown procedural material type '" + t + "'");
  const size_t count = static_cast<size_t>(n) * n;
  std::vector<uint8_t> albedo(count * 3), mr(count * 3), normal(count * 3);
  std::vector<float> height(count);
  // rows are independent (file comment): spread over the cores, the same bytes on any count.
  ThreadPool pool(0);
  pool.ParallelFor(n, [&](int64_t row) {
    const int y = static_cast<int>(row);
    for (int x = 0; x < n; ++x) {
      const Texel tx = (gen.*fn)((x + 0.5f) / n, (y + 0.5f) / n);
      const size_t i = static_cast<size_t>(y) * n + x;
      for (int c = 0; c < 3; ++c) albedo[3 * i + c] = EncodeSrgb8(tx.albedo[c]);
      // data maps hold sRGB-encoded values (render/material/material_eval.h, "PBR maps")
      mr[3 * i] = 0;
      mr[3 * i + 1] = EncodeSrgb8(tx.roughness);
      mr[3 * i + 2] = EncodeSrgb8(tx.metallic);
      height[i] = tx.height_m;
    }
  });
  // normals by central differences (wrapped), x along +u, y towards the top row
  const float texel_m = static_cast<float>(out.size_m) / n;
  pool.ParallelFor(n, [&](int64_t row) {
    const int y = static_cast<int>(row);
    for (int x = 0; x < n; ++x) {
      auto h = [&](int xi, int yi) {
        return height[static_cast<size_t>(Wrap(yi, n)) * n + Wrap(xi, n)];
      };
      const float dhdx = (h(x + 1, y) - h(x - 1, y)) / (2 * texel_m);
      const float dhdy = (h(x, y - 1) - h(x, y + 1)) / (2 * texel_m);
      Eigen::Vector3f nn(-dhdx, -dhdy, 1);
      nn.normalize();
      const size_t i = static_cast<size_t>(y) * n + x;
      for (int c = 0; c < 3; ++c) normal[3 * i + c] = EncodeSrgb8((nn[c] + 1) * 0.5f);
    }
  });
  out.albedo = MakeImage(n, std::move(albedo));
  out.metal_roughness = MakeImage(n, std::move(mr));
  out.normal = MakeImage(n, std::move(normal));
  return out;
}

std::string ProceduralMaterialKey(const ProceduralMaterialConfig& config) {
  const double size_m = ImageSide(config);
  std::string color = "default";
  if (config.color)
    color = fmt::format("{:.9g},{:.9g},{:.9g}", config.color->x(), config.color->y(),
                        config.color->z());
  return fmt::format(
      "penumbra-procedural v{} type={} seed={} size_m={:.17g} resolution={} color={}",
      kProceduralMaterialVersion, config.type, config.seed, size_m, config.resolution, color);
}

namespace {

constexpr char kMapsMagic[8] = {'P', 'N', 'M', 'A', 'P', 'S', '0', '1'};

// the cache file: magic, key length (uint32) and key, then the level-0 bytes of the albedo,
// metallic-roughness and normal maps (resolution^2 x 3 each).
std::filesystem::path MapsPath(const std::string& cache_dir, const std::string& key) {
  return std::filesystem::path(cache_dir) / fmt::format("{:016x}.pmaps", Fnv1a64(key));
}

std::optional<ProceduralMaps> LoadMaps(const std::filesystem::path& path, const std::string& key,
                                       int n, double size_m) {
  std::string bytes;
  try {
    bytes = ReadInputFile(path, "procedural material cache file");
  } catch (const ConfigError&) {
    return std::nullopt;  // absent, unreadable or too large: generate again
  }
  const size_t map_bytes = static_cast<size_t>(n) * n * 3;
  const size_t head = sizeof kMapsMagic + sizeof(uint32_t) + key.size();
  if (bytes.size() != head + 3 * map_bytes || std::memcmp(bytes.data(), kMapsMagic, 8) != 0)
    return std::nullopt;
  uint32_t key_len = 0;
  std::memcpy(&key_len, bytes.data() + 8, sizeof key_len);
  if (key_len != key.size() || bytes.compare(12, key.size(), key) != 0) return std::nullopt;
  auto map = [&](int k) {
    const char* p = bytes.data() + head + k * map_bytes;
    return MakeImage(n, std::vector<uint8_t>(p, p + map_bytes));
  };
  ProceduralMaps maps;
  maps.albedo = map(0);
  maps.metal_roughness = map(1);
  maps.normal = map(2);
  maps.size_m = size_m;
  return maps;
}

}  // namespace

ProceduralMaps CachedProceduralMaterial(const ProceduralMaterialConfig& config,
                                        const std::string& cache_dir, bool* cache_hit) {
  const std::string key = ProceduralMaterialKey(config);
  const double size_m = ImageSide(config);
  const std::filesystem::path path = MapsPath(cache_dir, key);
  if (std::optional<ProceduralMaps> hit = LoadMaps(path, key, config.resolution, size_m)) {
    if (cache_hit) *cache_hit = true;
    return *std::move(hit);
  }
  if (cache_hit) *cache_hit = false;
  ProceduralMaps maps = GenerateProceduralMaterial(config);
  try {
    std::error_code ec;
    std::filesystem::create_directories(cache_dir, ec);
    std::string bytes(kMapsMagic, sizeof kMapsMagic);
    const uint32_t key_len = static_cast<uint32_t>(key.size());
    bytes.append(reinterpret_cast<const char*>(&key_len), sizeof key_len);
    bytes += key;
    for (const auto& im : {maps.albedo, maps.metal_roughness, maps.normal})
      bytes.append(reinterpret_cast<const char*>(im->rgb_srgb().data()), im->rgb_srgb().size());
    WriteFileAtomic(path, bytes);
  } catch (const std::exception& e) {
    // a cache that cannot be written costs the next load time, nothing else.
    spdlog::warn("procedural material cache not written: {}", e.what());
  }
  return maps;
}

void ApplyProceduralMaterials(const std::vector<ProceduralMaterialEntry>& entries,
                              const std::string& world_file, SceneDescription* scene) {
  for (const ProceduralMaterialEntry& o : entries) {
    const int k = scene->FindMaterial(o.material);
    if (k < 0)
      throw ConfigError(world_file, o.line, "materials." + o.material,
                        "no material with that name; expected a prefixed material name such as "
                        "'<model>/<material>'");
    const ProceduralMaps maps = CachedProceduralMaterial(o.config, DefaultCacheDir("materials"));
    auto add = [&](const std::shared_ptr<const TextureImage>& image, const char* map) {
      Texture t;
      t.name = o.material + "/" + map;
      t.kind = Texture::Kind::k2D;
      t.image = image;
      scene->textures.push_back(std::move(t));
      return static_cast<int>(scene->textures.size()) - 1;
    };
    Material& m = scene->materials[k];
    m.texture = add(maps.albedo, "albedo");
    add(maps.metal_roughness, "metallic_roughness");
    add(maps.normal, "normal");
    m.base_color = Eigen::Vector3f::Ones();
    m.roughness = 1;
    m.metallic = 1;
    m.texuniform = true;
    const float r = static_cast<float>(2.0 / maps.size_m);  // MuJoCo: texrepeat / 2 per metre
    m.texrepeat = {r, r};
  }
}

}  // namespace penumbra
