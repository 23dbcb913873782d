#pragma once
// the output folder of a run (--out): a run writes into an empty or new folder only, so
// that no stale frame of an earlier run can sit next to this run's files. with `force`,
// the outputs of an earlier Penumbra run are removed first, and nothing else: a file
// Penumbra does not write, or any symbolic link, makes the run refuse (and is left alone).
//
// Penumbra's outputs (README "Outputs"): run.json, composed.xml, trajectory.csv,
// camera_info.{yaml,json}, semantic_classes.json, rig.json, run logs *.plog (--record);
// lidar/**/{index.csv,scan_*.pcd}; imu/**, sensors/**, ground_truth/** *.csv; camera folders
// (any other folder, nested for "<model>/<camera>") holding intrinsics.json, frames.csv and image
// folders rgb, depth, segmentation, range, normals, instance_segmentation, semantic_segmentation of
// NNNNNN.png; and the temporary files a killed run can leave (core/output_file.h).

#include <filesystem>
#include <string>
#include <vector>

#include "penumbra/output/output_lock.h"

namespace penumbra {

/// paths (relative to `out`) under `out` that are not outputs of a Penumbra run, and
/// symbolic links (never followed); at most `limit` of them.
/// @throws Error if `out` cannot be listed.
std::vector<std::string> ForeignOutputEntries(const std::filesystem::path& out, size_t limit = 10);

/// makes `out` ready for a run: creates it if missing and locks it (LockOutputFolder: one run
/// per folder); an empty folder is used as is; a non-empty one is refused unless `force`, which
/// removes the outputs of an earlier run when everything in it is one (ForeignOutputEntries is
/// empty) and refuses otherwise. the lock is taken before anything is removed, so a folder a
/// live run holds is never emptied.
/// @param key  where `out` came from, named in errors: "--out" or the world file's "output.dir"
/// @returns the folder's lock: hold it for the whole run
/// @throws ConfigError (key `key`) if `out` is not a folder, cannot be created, is in use by
///         another run (naming its PID), is not empty without `force`, or holds anything but
///         Penumbra outputs (named, up to 10).
OutputLock PrepareOutputFolder(const std::filesystem::path& out, bool force,
                               const std::string& key = "--out");

/// refuses an output folder (`out_dir`, --out) of a replay or resimulation that holds the
/// run log it reads (`log_path`) (or is its folder's parent): --force would empty it.
/// @throws ConfigError("--out") naming both.
void RefuseOutputFolderHoldingLog(const std::string& out_dir, const std::string& log_path);

/// a run refused while it sets up (bad input found once the model is composed: an unknown
/// body, a scene too large) leaves its output folder as it found it, empty or absent, so that
/// the corrected command runs without --force. everything in the folder is the run's own: it
/// was empty or new when the run began (PrepareOutputFolder). unless Dismiss() was called, the
/// destructor removes the folder (`created`) or everything in it; errors are ignored.
class SetupRollback {
 public:
  /// `out`: the output folder; `created`: PrepareOutputFolder created it (it did not exist).
  SetupRollback(std::filesystem::path out, bool created);
  SetupRollback(const SetupRollback&) = delete;
  SetupRollback& operator=(const SetupRollback&) = delete;
  ~SetupRollback();
  /// the run has started: from here on what it wrote is kept.
  void Dismiss() { done_ = true; }

 private:
  std::filesystem::path out_;
  bool created_ = false;
  bool done_ = false;
};

}  // namespace penumbra
