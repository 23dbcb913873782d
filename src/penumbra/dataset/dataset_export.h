#pragma once
// `penumbra export`: a run's output folder (dataset/run_folder.h) written in a public dataset
// layout: TUM RGB-D (dataset/tum_export.h), EuRoC/ASL (dataset/euroc_export.h) or KITTI
// odometry (dataset/kitti_export.h). docs/datasets.md states each format's frames and
// timestamps and how Penumbra's map to them.
//
// the dataset is written into a new folder beside the output folder,
// "<out>.export-tmp-<pid>-<random>", and renamed to the output folder only when it is complete: the
// output folder never holds a partial dataset (no images without their index files), and an
// export that fails or is stopped (DatasetExportOptions::stop_request) removes the temporary
// folder, leaving the output folder as it was. one that a killed export left behind is removed
// by the next export into the same parent folder (RemoveStaleExportTemps).

#include <atomic>
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "penumbra/core/output_path_policy.h"
#include "penumbra/dataset/run_folder.h"

namespace penumbra {

enum class DatasetFormat { kTum, kEuroc, kKitti };

/// "tum", "euroc", "kitti" -> the format.
/// @throws ConfigError (key "--format") for any other name, listing the names.
DatasetFormat ParseDatasetFormat(const std::string& name);

/// what to export and where.
struct DatasetExportOptions {
  DatasetFormat format = DatasetFormat::kTum;
  /// output folder: created if missing; an existing one must be empty.
  std::filesystem::path out_dir;
  /// camera (cam0 / image_0 / the TUM camera); empty = the run's only camera.
  std::string camera;
  /// second camera (EuRoC cam1, KITTI image_1); empty = none. not used by TUM.
  std::string camera2;
  /// IMU (EuRoC imu0); empty = the run's only IMU. used by EuRoC only.
  std::string imu;
  /// KITTI sequence name: two digits.
  std::string sequence = "00";
  /// what the TUM lists' "# file:" line and penumbra_export.yaml name as the source; "" = the
  /// run folder, relative to out_dir (PathRelativeTo). (a run log exported through a temporary
  /// replay folder names the log.)
  std::string source_label;
  /// what the run's depth images are, for the dataset's penumbra_export.yaml (TUM):
  /// `depth_source` "sensor_model" (with `depth_model`, a sensors/depth_noise.h preset),
  /// "ground_truth" (exact z-depth) or "as_recorded" (as the run's camera wrote them: its
  /// world-file depth_noise if it had one, else exact); `depth_note` says how it was made.
  std::string depth_source = "as_recorded";
  std::string depth_model;
  std::string depth_note;
  /// a stop request (SIGINT / SIGTERM; null = none), read between frames: when it reads
  /// non-zero the export throws ExportStopped (dataset/export_stop.h) and leaves nothing behind.
  const std::atomic<int>* stop_request = nullptr;

  /// @throws ConfigError naming the option (--out, --camera2, --imu, --sequence) for an empty
  ///         output folder, a second camera with TUM or equal to the first, an IMU without
  ///         EuRoC, or a sequence that is not two digits.
  void ValidateOrThrow() const;
};

/// what was exported.
struct DatasetExportSummary {
  std::string camera, camera2, imu;  ///< the sensors used ("" = none)
  int64_t frames = 0;                ///< images per camera
  int64_t imu_samples = 0;           ///< EuRoC only
  int64_t depth_beyond_range = 0;    ///< TUM only: depth pixels beyond 13.107 m, written as 0
};

/// checks that `out` can receive a dataset: missing, or an empty folder that is not a
/// symbolic link.
/// @throws ConfigError (key "--out") if it is a file, a symbolic link or a folder that is not
///         empty.
void CheckExportFolder(const std::filesystem::path& out);

/// temporary outputs of an export live beside their destination until they are complete:
/// "<out's name>" + suffix + "-" + the creating process's PID + "-" + 12 random hex digits
/// (suffix ".export-tmp" for datasets and bags, ".replay-tmp" for the run folder a run log is
/// replayed into). the creator holds an flock on it while it works (where `lock` is given), so
/// that one left behind by a killed export (SIGKILL leaves it) can be told from one in use:
/// RemoveStaleExportTemps removes the former and never the latter.

/// a new, empty folder beside `out` (same parent, created if missing), named as above, made
/// with mkdir (never an existing one; permissions from the umask). with `lock`, *lock receives
/// a descriptor of the folder holding an exclusive flock, kept until the caller closes it.
/// @throws Error naming the folder if it cannot be created or locked.
std::filesystem::path MakeSiblingTempFolder(const std::filesystem::path& out,
                                            const std::string& suffix, UniqueFd* lock = nullptr);

/// a new, empty file beside `out` (same parent, which must exist), named as above, created with
/// O_EXCL | O_NOFOLLOW (never an existing file or a link; permissions 0666 less the umask);
/// *lock receives its descriptor (O_WRONLY) holding an exclusive flock.
/// @throws Error naming `out` if it cannot be created or locked.
std::filesystem::path MakeSiblingTempFile(const std::filesystem::path& out,
                                          const std::string& suffix, UniqueFd* lock);

/// the PID in the name of a temporary export output (see above), or 0 when `name` is not one.
int64_t ExportTempOwner(std::string_view name);

/// removes what killed exports left beside `out`: every folder or regular file in out's parent
/// folder (not a link; owned by this user) named as a temporary export output whose process is
/// gone (kill(pid, 0) fails with ESRCH) and on which no process holds an flock (one a live
/// export holds is never touched, even if its PID was reused or belongs to another PID
/// namespace). errors while listing or removing are ignored (best effort).
/// @returns the paths removed.
std::vector<std::filesystem::path> RemoveStaleExportTemps(const std::filesystem::path& out);

/// `target` as a path relative to the folder `from`, for the files of a dataset to name their
/// source without an absolute path (it still leads there from the dataset's folder): both made
/// absolute, with symbolic links of their existing parts resolved (std::filesystem::
/// weakly_canonical); `target` absolute, normalised, when the two have no common root.
std::string PathRelativeTo(const std::filesystem::path& target, const std::filesystem::path& from);

/// the text of the dataset's penumbra_export.yaml: source, format, cameras and (TUM) the
/// depth block of `options` (docs/datasets.md "penumbra_export.yaml").
std::string ExportMetadataYaml(const DatasetExportOptions& options, const std::string& source,
                               const DatasetExportSummary& summary);

/// exports `run` as `options` says (options.ValidateOrThrow() and CheckExportFolder first; the
/// inputs are read before anything is written), into a temporary sibling folder renamed to
/// options.out_dir when complete; the folder also gets penumbra_export.yaml
/// (ExportMetadataYaml).
/// @throws ConfigError for a camera or IMU the run does not have (listing those it has), a
///         run with several cameras or IMUs and none named, and the format's own errors
///         (see the format headers); Error if a file cannot be written; ExportStopped when
///         options.stop_request is set. in every case nothing is left in or beside out_dir.
DatasetExportSummary ExportDataset(const RunFolder& run, const DatasetExportOptions& options);

}  // namespace penumbra
