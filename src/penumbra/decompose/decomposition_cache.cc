#include "penumbra/decompose/decomposition_cache.h"

#include <fmt/format.h>
#include <openssl/evp.h>
#include <unistd.h>

#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>
#include <vector>

#include "penumbra/core/cache_dir.h"
#include "penumbra/core/error.h"
#include "penumbra/core/input_file.h"

namespace penumbra {
namespace {

constexpr char kMagic[8] = {'P', 'N', 'B', 'D', 'C', 'M', 'P', '1'};

class Bytes {
 public:
  template <typename T>
  void Put(const T& v) {
    const char* p = reinterpret_cast<const char*>(&v);
    data_.insert(data_.end(), p, p + sizeof(T));
  }
  void PutMesh(const SolidMesh& mesh) {
    Put<uint64_t>(mesh.vertices.size());
    for (const Eigen::Vector3d& v : mesh.vertices) Put(v.x()), Put(v.y()), Put(v.z());
    Put<uint64_t>(mesh.triangles.size());
    for (const auto& t : mesh.triangles) Put<int32_t>(t[0]), Put<int32_t>(t[1]), Put<int32_t>(t[2]);
  }
  const std::vector<char>& data() const { return data_; }

 private:
  std::vector<char> data_;
};

class Reader {
 public:
  explicit Reader(const std::string& bytes) : bytes_(bytes) {}
  template <typename T>
  bool Get(T* v) {
    if (pos_ + sizeof(T) > bytes_.size()) return false;
    std::memcpy(v, bytes_.data() + pos_, sizeof(T));
    pos_ += sizeof(T);
    return true;
  }
  bool GetMesh(SolidMesh* mesh) {
    uint64_t nv = 0, nt = 0;
    if (!Get(&nv) || nv > (bytes_.size() - pos_) / 24) return false;
    mesh->vertices.resize(nv);
    for (auto& v : mesh->vertices)
      if (!Get(&v.x()) || !Get(&v.y()) || !Get(&v.z())) return false;
    if (!Get(&nt) || nt > (bytes_.size() - pos_) / 12) return false;
    mesh->triangles.resize(nt);
    for (auto& t : mesh->triangles) {
      int32_t a, b, c;
      if (!Get(&a) || !Get(&b) || !Get(&c)) return false;
      if (a < 0 || b < 0 || c < 0 || static_cast<uint64_t>(std::max({a, b, c})) >= nv) return false;
      t = {a, b, c};
    }
    return true;
  }
  bool done() const { return pos_ == bytes_.size(); }

 private:
  const std::string& bytes_;
  size_t pos_ = 0;
};

}  // namespace

std::string DefaultDecompositionCacheDir() { return DefaultCacheDir("decompose"); }

std::string DecompositionKey(const SolidMesh& mesh, const DecompositionOptions& o) {
  Bytes b;
  for (char c : std::string("penumbra-decompose")) b.Put(c);
  b.Put<int32_t>(kDecompositionVersion);
  b.Put<int32_t>(static_cast<int32_t>(o.method));
  b.Put(o.concavity_threshold);
  b.Put<int32_t>(o.max_parts);
  b.Put<int32_t>(o.max_cuts);
  b.Put<int32_t>(o.mcts_iterations);
  b.Put<int32_t>(o.mcts_depth);
  b.Put<int32_t>(o.planes_per_axis);
  b.Put<int32_t>(o.rollout_planes);
  b.Put<int32_t>(o.search_samples);
  b.Put<uint8_t>(o.merge ? 1 : 0);
  b.Put<uint64_t>(o.seed);
  b.Put<int32_t>(o.concavity.samples);
  b.Put(o.concavity.rv_k);
  b.PutMesh(mesh);
  unsigned char digest[EVP_MAX_MD_SIZE];
  unsigned int len = 0;
  EVP_Digest(b.data().data(), b.data().size(), digest, &len, EVP_sha256(), nullptr);
  std::string hex;
  for (unsigned int i = 0; i < len; ++i) hex += fmt::format("{:02x}", digest[i]);
  return hex;
}

std::string DecompositionCache::PathOf(const std::string& key) const {
  return (std::filesystem::path(dir_) / (key + ".pdc")).string();
}

std::optional<Decomposition> DecompositionCache::Load(const std::string& key) const {
  std::string bytes;
  try {
    bytes = ReadInputFile(PathOf(key), "decomposition cache file");
  } catch (const ConfigError&) {
    return std::nullopt;  // absent, unreadable or too large: decompose again
  }
  Reader r(bytes);
  char magic[8];
  for (char& c : magic)
    if (!r.Get(&c)) return std::nullopt;
  if (std::memcmp(magic, kMagic, 8) != 0) return std::nullopt;
  Decomposition d;
  int32_t method = 0, cuts = 0;
  uint8_t cut_limit = 0, part_limit = 0;
  uint64_t n = 0;
  if (!r.Get(&method) || method < 0 || method > 2 || !r.Get(&d.mesh_volume) || !r.Get(&d.extent) ||
      !r.Get(&d.max_concavity) || !r.Get(&cuts) || !r.Get(&cut_limit) || !r.Get(&part_limit) ||
      !r.Get(&n) || n > bytes.size())
    return std::nullopt;
  d.method = static_cast<DecompositionMethod>(method);
  d.cuts = cuts;
  d.hit_cut_limit = cut_limit != 0;
  d.hit_part_limit = part_limit != 0;
  d.parts.resize(n);
  for (ConvexPart& part : d.parts)
    if (!r.Get(&part.volume) || !r.Get(&part.concavity) || !r.GetMesh(&part.hull))
      return std::nullopt;
  if (!r.done()) return std::nullopt;
  return d;
}

void DecompositionCache::Store(const std::string& key, const Decomposition& d) const {
  namespace fs = std::filesystem;
  std::error_code ec;
  fs::create_directories(dir_, ec);
  if (ec)
    throw Error(dir_ + ": cannot create the decomposition cache folder (" + ec.message() + ")");
  Bytes b;
  for (char c : kMagic) b.Put(c);
  b.Put<int32_t>(static_cast<int32_t>(d.method));
  b.Put(d.mesh_volume);
  b.Put(d.extent);
  b.Put(d.max_concavity);
  b.Put<int32_t>(d.cuts);
  b.Put<uint8_t>(d.hit_cut_limit ? 1 : 0);
  b.Put<uint8_t>(d.hit_part_limit ? 1 : 0);
  b.Put<uint64_t>(d.parts.size());
  for (const ConvexPart& part : d.parts) {
    b.Put(part.volume);
    b.Put(part.concavity);
    b.PutMesh(part.hull);
  }
  const std::string path = PathOf(key);
  const std::string tmp = fmt::format("{}.tmp{}", path, static_cast<long>(::getpid()));
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    out.write(b.data().data(), static_cast<std::streamsize>(b.data().size()));
    if (!out) throw Error(tmp + ": cannot write the decomposition cache entry");
  }
  fs::rename(tmp, path, ec);
  if (ec) throw Error(path + ": cannot store the decomposition cache entry (" + ec.message() + ")");
}

CachedDecomposition DecomposeCached(const SolidMesh& mesh, const DecompositionOptions& options,
                                    const DecompositionCache& cache, const std::string& name) {
  options.ValidateOrThrow();
  CachedDecomposition out;
  out.key = DecompositionKey(mesh, options);
  if (auto hit = cache.Load(out.key)) {
    out.decomposition = std::move(*hit);
    out.cache_hit = true;
    return out;
  }
  out.decomposition = DecomposeMesh(mesh, options, name);
  cache.Store(out.key, out.decomposition);
  return out;
}

}  // namespace penumbra
