#include "penumbra/dataset/dataset_export.h"

#include <fcntl.h>
#include <fmt/format.h>
#include <signal.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cctype>
#include <cerrno>
#include <charconv>
#include <cstdio>
#include <cstring>
#include <functional>
#include <limits>
#include <optional>
#include <random>
#include <system_error>

#include "penumbra/core/error.h"
#include "penumbra/core/output_file.h"
#include "penumbra/dataset/euroc_export.h"
#include "penumbra/dataset/export_stop.h"
#include "penumbra/dataset/kitti_export.h"
#include "penumbra/dataset/tum_export.h"

namespace penumbra {
namespace {

namespace fs = std::filesystem;

// the suffixes of temporary export outputs (dataset_export.h)
constexpr std::string_view kExportTempSuffixes[] = {".export-tmp", ".replay-tmp"};

std::mt19937_64 SeededRng() {
  std::random_device seed;
  return std::mt19937_64((static_cast<uint64_t>(seed()) << 32) ^ seed());
}

// "<name><suffix>-<pid>-<12 random hex digits>"
std::string TempName(const std::string& name, const std::string& suffix, std::mt19937_64& rng) {
  return fmt::format("{}{}-{}-{:012x}", name, suffix, static_cast<int64_t>(::getpid()),
                     rng() & 0xffffffffffffULL);
}

// a descriptor of the new temporary `p` (opened with `flags`) holding an exclusive flock
UniqueFd LockTemp(const fs::path& p, int flags, mode_t mode) {
  UniqueFd fd(::open(p.c_str(), flags, mode));
  if (fd.get() < 0 || ::flock(fd.get(), LOCK_EX | LOCK_NB) != 0)
    throw Error("cannot lock the temporary folder " + p.string() + ": " + std::strerror(errno));
  return fd;
}

// the named sensor, or the only one when none is named
std::string Pick(const std::string& named, const std::vector<std::string>& names,
                 const std::string& option, const std::string& what) {
  if (!named.empty()) return named;
  if (names.size() == 1) return names[0];
  std::string list;
  for (const std::string& n : names) list += (list.empty() ? "" : ", ") + n;
  if (names.empty())
    throw ConfigError("", 0, option, "the run has no " + what + "; expected a run with one");
  throw ConfigError("", 0, option,
                    "the run has " + std::to_string(names.size()) + " " + what +
                        "s; expected one named with " + option + " (" + list + ")");
}

// the format's export into `dir`; `prepare` makes the folder once the inputs are read
void Export(const RunFolder& run, const DatasetExportOptions& options, const RunCamera& cam0,
            const std::optional<RunCamera>& cam1, const std::string& source,
            const std::function<fs::path()>& prepare, DatasetExportSummary* summary) {
  const std::atomic<int>* stop = options.stop_request;
  if (options.format == DatasetFormat::kTum) {
    const fs::path dir = prepare();
    const TumExportResult r = ExportTum(cam0, source, dir, stop);
    summary->frames = r.frames;
    summary->depth_beyond_range = r.depth_beyond_range;
    return;
  }
  if (options.format == DatasetFormat::kKitti) {
    const fs::path dir = prepare();
    summary->frames = ExportKitti(cam0, cam1 ? &*cam1 : nullptr, options.sequence, dir, stop);
    return;
  }
  const std::vector<std::string> imus = run.ImuNames();
  if (imus.empty())
    throw ConfigError((run.dir() / "rig.json").string(), 0, "imus",
                      "the run has no IMU; EuRoC needs one (imu0): expected a run of a world "
                      "with an IMU (`type: imu` in its `sensors:`, docs/world-file.md), or "
                      "--format tum or kitti, which need cameras only");
  summary->imu = Pick(options.imu, imus, "--imu", "IMU");
  const RunImu imu = run.ReadImu(summary->imu);
  auto mounted = [&](const RunCamera& c) {
    const std::optional<RunMount> m = run.CameraMount(c.name);
    if (!m)
      throw ConfigError((run.dir() / "rig.json").string(), 0, "cameras",
                        "camera '" + c.name +
                            "' has no fixed mount (an MJCF camera, or a run older than "
                            "rig.json); EuRoC needs T_BS, expected a world-file camera");
    return EurocCamera{c, *m};
  };
  std::optional<EurocCamera> e1;
  if (cam1) e1 = mounted(*cam1);
  const EurocCamera e0 = mounted(cam0);
  const fs::path dir = prepare();
  const EurocExportResult r = ExportEuroc(e0, e1, imu, dir, stop);
  summary->frames = r.frames;
  summary->imu_samples = r.imu_samples;
}

}  // namespace

DatasetFormat ParseDatasetFormat(const std::string& name) {
  if (name == "tum") return DatasetFormat::kTum;
  if (name == "euroc") return DatasetFormat::kEuroc;
  if (name == "kitti") return DatasetFormat::kKitti;
  throw ConfigError("", 0, "--format",
                    "unknown format '" + name + "'; expected tum, euroc or kitti");
}

void DatasetExportOptions::ValidateOrThrow() const {
  if (out_dir.empty()) throw ConfigError("", 0, "--out", "empty; expected an output folder");
  if (!camera2.empty() && format == DatasetFormat::kTum)
    throw ConfigError("", 0, "--camera2",
                      "TUM RGB-D has one camera; expected --camera2 with euroc or kitti only");
  if (!camera2.empty() && camera2 == camera)
    throw ConfigError("", 0, "--camera2",
                      "'" + camera2 + "' is --camera too; expected another camera");
  if (!imu.empty() && format != DatasetFormat::kEuroc)
    throw ConfigError("", 0, "--imu", "only EuRoC has an IMU; expected --imu with euroc only");
  if (sequence.size() != 2 || !std::isdigit(static_cast<unsigned char>(sequence[0])) ||
      !std::isdigit(static_cast<unsigned char>(sequence[1])))
    throw ConfigError("", 0, "--sequence", "'" + sequence + "'; expected two digits (00 .. 99)");
}

void CheckExportFolder(const fs::path& out) {
  std::error_code ec;
  const fs::file_status st = fs::symlink_status(out, ec);
  if (!fs::exists(st)) return;
  if (fs::is_symlink(st))
    throw ConfigError("", 0, "--out",
                      "'" + out.string() +
                          "' is a symbolic link; expected a new or empty folder (the dataset "
                          "is renamed into place, which would replace the link)");
  if (!fs::is_directory(st))
    throw ConfigError("", 0, "--out",
                      "'" + out.string() + "' is not a folder; expected a new or empty folder");
  if (!fs::is_empty(out, ec))
    throw ConfigError("", 0, "--out",
                      "'" + out.string() + "' is not empty; expected a new or empty folder");
}

fs::path MakeSiblingTempFolder(const fs::path& out, const std::string& suffix, UniqueFd* lock) {
  fs::path target = fs::absolute(out).lexically_normal();
  if (target.filename().empty()) target = target.parent_path();  // "DIR/"
  const fs::path parent = target.parent_path();
  std::error_code ec;
  fs::create_directories(parent, ec);
  if (ec) throw Error("cannot create the folder " + parent.string() + ": " + ec.message());
  std::mt19937_64 rng = SeededRng();
  for (int attempt = 0; attempt < 100; ++attempt) {
    const fs::path p = parent / TempName(target.filename().string(), suffix, rng);
    if (::mkdir(p.c_str(), 0777) == 0) {
      if (lock) {
        try {
          *lock = LockTemp(p, O_RDONLY | O_DIRECTORY | O_NOFOLLOW | O_CLOEXEC, 0);
        } catch (const Error&) {
          ::rmdir(p.c_str());
          throw;
        }
      }
      return p;
    }
    if (errno != EEXIST)
      throw Error("cannot create the folder " + p.string() + ": " + std::strerror(errno));
  }
  throw Error("cannot create a temporary folder beside " + target.string());
}

fs::path MakeSiblingTempFile(const fs::path& out, const std::string& suffix, UniqueFd* lock) {
  const fs::path target = fs::absolute(out).lexically_normal();
  std::mt19937_64 rng = SeededRng();
  for (int attempt = 0; attempt < 100; ++attempt) {
    const fs::path p = target.parent_path() / TempName(target.filename().string(), suffix, rng);
    UniqueFd fd(::open(p.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0666));
    if (fd.get() >= 0) {
      if (::flock(fd.get(), LOCK_EX | LOCK_NB) != 0) {
        const int err = errno;
        ::unlink(p.c_str());
        throw Error("cannot lock " + p.string() + ": " + std::strerror(err));
      }
      *lock = std::move(fd);
      return p;
    }
    if (errno != EEXIST)
      throw Error("cannot create " + p.string() + " beside " + out.string() + ": " +
                  std::strerror(errno));
  }
  throw Error("cannot create a temporary file beside " + out.string());
}

int64_t ExportTempOwner(std::string_view name) {
  for (std::string_view suffix : kExportTempSuffixes) {
    const std::string marker = std::string(suffix) + "-";
    const size_t at = name.rfind(marker);
    if (at == std::string_view::npos || at == 0) continue;
    const std::string_view rest = name.substr(at + marker.size());
    const size_t dash = rest.find('-');
    if (dash == std::string_view::npos || dash == 0 || dash > 10) continue;
    const std::string_view hex = rest.substr(dash + 1);
    if (hex.size() != 12 || hex.find_first_not_of("0123456789abcdef") != std::string_view::npos)
      continue;
    int64_t pid = 0;
    const std::string_view digits = rest.substr(0, dash);
    const auto [end, err] = std::from_chars(digits.data(), digits.data() + digits.size(), pid);
    if (err != std::errc() || end != digits.data() + digits.size() || pid <= 0 ||
        pid > std::numeric_limits<pid_t>::max())
      continue;
    return pid;
  }
  return 0;
}

std::vector<fs::path> RemoveStaleExportTemps(const fs::path& out) {
  fs::path target = fs::absolute(out).lexically_normal();
  if (target.filename().empty()) target = target.parent_path();
  const fs::path parent = target.parent_path();
  std::vector<fs::path> removed;
  std::error_code ec;
  fs::directory_iterator it(parent, ec);
  if (ec) return removed;
  for (; it != fs::directory_iterator(); it.increment(ec)) {
    if (ec) break;
    const fs::path p = it->path();
    const int64_t pid = ExportTempOwner(p.filename().string());
    if (pid == 0) continue;
    // the creator still runs (or another user's process has its PID): in use, or not ours
    if (::kill(static_cast<pid_t>(pid), 0) == 0 || errno != ESRCH) continue;
    // O_NONBLOCK: nothing of that name blocks the open; O_NOFOLLOW: a link is left alone
    const UniqueFd fd(::open(p.c_str(), O_RDONLY | O_NOFOLLOW | O_NONBLOCK | O_CLOEXEC));
    if (fd.get() < 0) continue;
    struct stat st {};
    if (::fstat(fd.get(), &st) != 0 || st.st_uid != ::geteuid()) continue;
    if (!S_ISDIR(st.st_mode) && !S_ISREG(st.st_mode)) continue;
    // an flock held by a live export (a reused PID, another PID namespace): in use
    if (::flock(fd.get(), LOCK_EX | LOCK_NB) != 0) continue;
    std::error_code rm;
    if (S_ISDIR(st.st_mode))
      fs::remove_all(p, rm);  // links inside are removed, not followed
    else
      fs::remove(p, rm);
    if (!rm) removed.push_back(p);
  }
  return removed;
}

std::string PathRelativeTo(const fs::path& target, const fs::path& from) {
  std::error_code ec;
  fs::path t = fs::weakly_canonical(fs::absolute(target), ec);
  if (ec) t = fs::absolute(target).lexically_normal();
  fs::path f = fs::weakly_canonical(fs::absolute(from), ec);
  if (ec) f = fs::absolute(from).lexically_normal();
  const fs::path rel = t.lexically_relative(f);
  return rel.empty() ? t.string() : rel.string();
}

std::string ExportMetadataYaml(const DatasetExportOptions& options, const std::string& source,
                               const DatasetExportSummary& summary) {
  // YAML single-quoted scalars: a quote is written twice
  auto q = [](const std::string& v) {
    std::string out = "'";
    for (char c : v) {
      if (c == '\'') out += '\'';
      out += (c == '\n' || c == '\r') ? ' ' : c;
    }
    return out + "'";
  };
  const char* format = options.format == DatasetFormat::kTum     ? "tum"
                       : options.format == DatasetFormat::kEuroc ? "euroc"
                                                                 : "kitti";
  std::string y = "# written by penumbra export (docs/datasets.md)\n";
  y += "source: " + q(source) + "\n";
  y += std::string("format: ") + format + "\n";
  y += "camera: " + q(summary.camera) + "\n";
  if (!summary.camera2.empty()) y += "camera2: " + q(summary.camera2) + "\n";
  if (!summary.imu.empty()) y += "imu: " + q(summary.imu) + "\n";
  if (options.format == DatasetFormat::kTum) {
    y += "depth:\n";
    y += "  source: " + options.depth_source + "\n";
    if (!options.depth_model.empty()) y += "  model: " + options.depth_model + "\n";
    if (!options.depth_note.empty()) y += "  note: " + q(options.depth_note) + "\n";
  }
  return y;
}

DatasetExportSummary ExportDataset(const RunFolder& run, const DatasetExportOptions& options) {
  options.ValidateOrThrow();
  DatasetExportSummary summary;
  summary.camera = Pick(options.camera, run.CameraNames(), "--camera", "camera");
  const RunCamera cam0 = run.ReadCamera(summary.camera);
  std::optional<RunCamera> cam1;
  if (!options.camera2.empty()) {
    summary.camera2 = options.camera2;
    cam1 = run.ReadCamera(options.camera2);
  }
  // every input is read before anything is written; the dataset goes into a temporary folder
  // beside out_dir, renamed to it when complete (rename(2) replaces an empty folder), removed
  // when the export fails or is stopped
  const std::string source = options.source_label.empty()
                                 ? PathRelativeTo(run.dir(), options.out_dir)
                                 : options.source_label;
  CheckExportFolder(options.out_dir);
  CheckExportStop(options.stop_request);
  // what killed exports left beside out_dir (their process gone, no lock held on them)
  RemoveStaleExportTemps(options.out_dir);
  std::optional<fs::path> temp;
  UniqueFd temp_lock;  // held while the export works: no other export removes the folder
  auto prepare = [&] {
    temp = MakeSiblingTempFolder(options.out_dir, ".export-tmp", &temp_lock);
    return *temp;
  };
  try {
    Export(run, options, cam0, cam1, source, prepare, &summary);
    if (temp)
      WriteFileAtomic(*temp / "penumbra_export.yaml", ExportMetadataYaml(options, source, summary));
    CheckExportStop(options.stop_request);
    if (temp && std::rename(temp->c_str(), options.out_dir.c_str()) != 0) {
      const int err = errno;
      if (err == ENOTEMPTY || err == EEXIST || err == ENOTDIR || err == EISDIR)
        throw ConfigError("", 0, "--out",
                          "'" + options.out_dir.string() +
                              "' was filled or replaced during the export; expected a new or "
                              "empty folder");
      throw Error("cannot rename " + temp->string() + " to " + options.out_dir.string() + ": " +
                  std::strerror(err));
    }
  } catch (...) {
    std::error_code ec;
    if (temp) fs::remove_all(*temp, ec);
    throw;
  }
  return summary;
}

}  // namespace penumbra
