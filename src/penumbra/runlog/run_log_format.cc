#include "penumbra/runlog/run_log_format.h"

#include <fmt/format.h>
#include <openssl/evp.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <cstring>

#include "penumbra/core/error.h"
#include "penumbra/core/input_file.h"

namespace penumbra {
namespace {

// SHA-256 over pieces fed by `feed` (OpenSSL EVP)
template <typename Feed>
std::string Sha256With(Feed&& feed) {
  EVP_MD_CTX* ctx = EVP_MD_CTX_new();
  if (!ctx || EVP_DigestInit_ex(ctx, EVP_sha256(), nullptr) != 1) {
    EVP_MD_CTX_free(ctx);
    throw RunLogError("SHA-256: OpenSSL could not set up a digest");
  }
  bool ok = true;
  feed([&](const void* data, size_t n) { ok = ok && EVP_DigestUpdate(ctx, data, n) == 1; });
  std::array<unsigned char, EVP_MAX_MD_SIZE> md{};
  unsigned int len = 0;
  ok = ok && EVP_DigestFinal_ex(ctx, md.data(), &len) == 1;
  EVP_MD_CTX_free(ctx);
  if (!ok) throw RunLogError("SHA-256: OpenSSL digest failed");
  std::string hex;
  hex.reserve(2 * len);
  for (unsigned int i = 0; i < len; ++i) hex += fmt::format("{:02x}", md[i]);
  return hex;
}

// the counts of RunLogLayout by StateDim (kStateDimNames order)
constexpr std::array<int RunLogLayout::*, kNumStateDims> kLayoutCounts = {
    &RunLogLayout::nq,           &RunLogLayout::nv,
    &RunLogLayout::na,           &RunLogLayout::nu,
    &RunLogLayout::nmocap,       &RunLogLayout::nuserdata,
    &RunLogLayout::nbody,        &RunLogLayout::num_controllers,
    &RunLogLayout::nhistory,     &RunLogLayout::neq,
    &RunLogLayout::npluginstate, &RunLogLayout::nplastic};

}  // namespace

StateDims RunLogLayout::dims() const {
  StateDims d;
  for (int i = 0; i < kNumStateDims; ++i) d.n[i] = this->*kLayoutCounts[i];
  return d;
}

void RunLogLayout::set_dims(const StateDims& d) {
  for (int i = 0; i < kNumStateDims; ++i) this->*kLayoutCounts[i] = static_cast<int>(d.n[i]);
}

std::string_view RunLogChunkKindName(RunLogChunkKind kind) {
  switch (kind) {
    case RunLogChunkKind::kHeader:
      return "header";
    case RunLogChunkKind::kSteps:
      return "steps";
    case RunLogChunkKind::kEvents:
      return "events";
    case RunLogChunkKind::kSensors:
      return "sensors";
    case RunLogChunkKind::kEnd:
      return "end";
  }
  return "unknown";
}

std::string Sha256Hex(std::string_view bytes) {
  return Sha256With([&](auto&& update) { update(bytes.data(), bytes.size()); });
}

std::string Sha256OfFile(const std::string& path, uint64_t* size_bytes) {
  // a regular file only (a log names its assets' paths: a FIFO there blocked, /dev/zero never
  // ended)
  InputFile file;
  try {
    file = OpenInputFile(path, "asset file");
  } catch (const ConfigError& e) {
    throw RunLogError(
        fmt::format("{}: cannot be read for its content hash: {}", path, e.problem()));
  }
  uint64_t total = 0;
  int read_error = 0;
  std::string hex = Sha256With([&](auto&& update) {
    std::array<char, 1 << 16> buf;
    while (true) {
      const ssize_t n = ::read(file.fd.get(), buf.data(), buf.size());
      if (n < 0 && errno == EINTR) continue;
      if (n < 0) read_error = errno;
      if (n <= 0) break;
      update(buf.data(), static_cast<size_t>(n));
      total += static_cast<uint64_t>(n);
    }
  });
  if (read_error != 0)
    throw RunLogError(
        fmt::format("{}: read error while hashing: {}", path, std::strerror(read_error)));
  if (size_bytes) *size_bytes = total;
  return hex;
}

}  // namespace penumbra
