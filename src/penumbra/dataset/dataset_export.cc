#include "penumbra/dataset/dataset_export.h"

#include <fmt/format.h>

#include <cctype>
#include <functional>
#include <optional>
#include <system_error>

#include "penumbra/core/error.h"
#include "penumbra/dataset/euroc_export.h"
#include "penumbra/dataset/kitti_export.h"
#include "penumbra/dataset/tum_export.h"

namespace penumbra {
namespace {

namespace fs = std::filesystem;

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

// the format's export into options.out_dir; `prepare` makes the folder once the inputs are read
void Export(const RunFolder& run, const DatasetExportOptions& options, const RunCamera& cam0,
            const std::optional<RunCamera>& cam1, const std::string& source,
            const std::function<void()>& prepare, DatasetExportSummary* summary) {
  if (options.format == DatasetFormat::kTum) {
    prepare();
    const TumExportResult r = ExportTum(cam0, source, options.out_dir);
    summary->frames = r.frames;
    summary->depth_beyond_range = r.depth_beyond_range;
    return;
  }
  if (options.format == DatasetFormat::kKitti) {
    prepare();
    summary->frames = ExportKitti(cam0, cam1 ? &*cam1 : nullptr, options.sequence, options.out_dir);
    return;
  }
  summary->imu = Pick(options.imu, run.ImuNames(), "--imu", "IMU");
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
  prepare();
  const EurocExportResult r = ExportEuroc(e0, e1, imu, options.out_dir);
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

void PrepareExportFolder(const fs::path& out) {
  std::error_code ec;
  if (fs::exists(fs::symlink_status(out, ec))) {
    if (!fs::is_directory(out, ec))
      throw ConfigError("", 0, "--out",
                        "'" + out.string() + "' is not a folder; expected a new or empty folder");
    if (!fs::is_empty(out, ec))
      throw ConfigError("", 0, "--out",
                        "'" + out.string() + "' is not empty; expected a new or empty folder");
    return;
  }
  fs::create_directories(out, ec);
  if (ec)
    throw ConfigError("", 0, "--out", "cannot create '" + out.string() + "': " + ec.message());
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
  // every input is read before the output folder is touched; a failed export removes what it
  // wrote (the folder too when it made it)
  const std::string source = options.source_label.empty()
                                 ? fs::absolute(run.dir()).lexically_normal().string()
                                 : options.source_label;
  std::error_code ec;
  const bool out_existed = fs::exists(fs::symlink_status(options.out_dir, ec));
  bool prepared = false;
  auto prepare = [&] {
    PrepareExportFolder(options.out_dir);
    prepared = true;
  };
  try {
    Export(run, options, cam0, cam1, source, prepare, &summary);
  } catch (...) {
    if (prepared) {
      if (!out_existed) {
        fs::remove_all(options.out_dir, ec);
      } else {
        for (const auto& e : fs::directory_iterator(options.out_dir, ec))
          fs::remove_all(e.path(), ec);
      }
    }
    throw;
  }
  return summary;
}

}  // namespace penumbra
