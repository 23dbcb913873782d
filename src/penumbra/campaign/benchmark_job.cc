#include "penumbra/campaign/benchmark_job.h"

#include <spdlog/spdlog.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>

#include "penumbra/campaign/benchmark_text.h"
#include "penumbra/campaign/command_template.h"
#include "penumbra/campaign/method_process.h"
#include "penumbra/campaign/nav_job.h"
#include "penumbra/core/error.h"
#include "penumbra/core/output_file.h"
#include "penumbra/dataset/dataset_export.h"
#include "penumbra/dataset/run_folder.h"
#include "penumbra/eval/trajectory.h"
#include "penumbra/eval/trajectory_evaluation.h"
#include "penumbra/replay/kinematic/replay_runner.h"
#include "penumbra/world/yaml_reader.h"

namespace penumbra {
namespace fs = std::filesystem;
namespace {

using namespace benchmark_text;  // NOLINT: module-internal helpers

nlohmann::json Num(double v) {
  return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr);
}
double NumOf(const nlohmann::json& j) { return j.is_number() ? j.get<double>() : NAN; }

nlohmann::json RowJson(const BenchmarkRow& r) {
  return {{"world", r.world},
          {"condition", r.condition},
          {"method", r.method},
          {"trial", r.trial},
          {"seed", r.seed},
          {"status", r.status},
          {"detail", r.detail},
          {"frames", r.frames},
          {"poses", r.poses},
          {"ate_rmse_m", Num(r.ate_rmse_m)},
          {"ate_mean_m", Num(r.ate_mean_m)},
          {"ate_max_m", Num(r.ate_max_m)},
          {"rpe_trans_rmse_m", Num(r.rpe_trans_rmse_m)},
          {"rpe_rot_rmse_deg", Num(r.rpe_rot_rmse_deg)},
          {"coverage", Num(r.coverage)},
          {"scaled_ate_m", Num(r.scaled_ate_m)},
          {"tracked_fraction", Num(r.tracked_fraction)},
          {"tracked_path_coverage", Num(r.tracked_path_coverage)},
          {"tracked_scaled_ate_m", Num(r.tracked_scaled_ate_m)},
          {"pose_fraction", Num(r.pose_fraction)},
          {"scale", Num(r.scale)},
          {"replay_sec", r.replay_sec},
          {"export_sec", r.export_sec},
          {"method_sec", r.method_sec},
          {"eval_sec", r.eval_sec}};
}

// the method's output read as a TUM trajectory in seconds
Trajectory ReadEstimate(const fs::path& file, const std::string& format) {
  Trajectory t = ReadTumTrajectory(file);
  if (format == "tum_ns")
    for (double& s : t.time_sec) s *= 1e-9;
  return t;
}

void Evaluate(const Trajectory& gt, const Trajectory& est, const BenchmarkSpec& spec,
              const BenchmarkMethod& m, const std::string& gt_name, const std::string& est_name,
              BenchmarkRow& row) {
  EvaluationOptions options;
  options.association.max_dt_sec = spec.metrics.max_dt_sec;
  options.alignment = m.align;
  options.rpe_delta.seconds = spec.metrics.rpe_delta_sec;
  TrajectoryEvaluation e;
  bool rpe = true;
  try {
    e = EvaluateTrajectory(gt, est, options, gt_name, est_name);
  } catch (const ConfigError&) {
    // no pose pair at the RPE interval (a short tracked stretch): ATE and the rest still count
    options.rpe_delta = RpeDelta{};
    e = EvaluateTrajectory(gt, est, options, gt_name, est_name);
    rpe = false;
  }
  row.ate_rmse_m = e.ate_m.rmse;
  row.ate_mean_m = e.ate_m.mean;
  row.ate_max_m = e.ate_m.max;
  if (rpe) {
    row.rpe_trans_rmse_m = e.rpe_translation_m.rmse;
    row.rpe_rot_rmse_deg = e.rpe_rotation_deg.rmse;
  }
  row.coverage = e.coverage;
  row.scaled_ate_m = e.scaled_ate_m;
  row.tracked_fraction = e.tracked.fraction;
  row.tracked_path_coverage = e.tracked_path_coverage;
  row.tracked_scaled_ate_m = e.tracked_scaled_ate_m;
  row.pose_fraction = e.pose_fraction;
  row.scale = e.alignment.scale;
}

}  // namespace

std::vector<BenchmarkJob> PlanBenchmarkJobs(const BenchmarkSpec& spec) {
  if (spec.kind == "nav") return PlanNavJobs(spec);
  std::vector<BenchmarkJob> jobs;
  for (size_t w = 0; w < spec.worlds.size(); ++w)
    for (size_t c = 0; c < spec.conditions.size(); ++c)
      for (size_t t = 0; t < spec.seeds.size(); ++t) {
        BenchmarkJob j;
        j.index = static_cast<int>(jobs.size());
        j.world = w;
        j.condition = c;
        j.trial = t;
        j.seed = spec.seeds[t];
        j.id = spec.worlds[w].name + "__" + spec.conditions[c].name + "__t" + std::to_string(t + 1);
        jobs.push_back(j);
      }
  return jobs;
}

std::string RecordingPath(const std::string& out_dir, const BenchmarkWorld& world) {
  return (fs::path(out_dir) / "recordings" / (world.name + ".plog")).string();
}

std::string JobFolder(const std::string& out_dir, const BenchmarkJob& job) {
  return (fs::path(out_dir) / "jobs" / job.id).string();
}

std::string JobResultPath(const std::string& out_dir, const BenchmarkJob& job) {
  return (fs::path(JobFolder(out_dir, job)) / "result.json").string();
}

std::vector<BenchmarkRow> RunBenchmarkJob(const BenchmarkSpec& spec, const BenchmarkJob& job,
                                          const BenchmarkJobContext& context) {
  const BenchmarkWorld& world = spec.worlds[job.world];
  const BenchmarkCondition& condition = spec.conditions[job.condition];
  const fs::path dir = JobFolder(context.out_dir, job);
  fs::remove_all(dir);
  fs::create_directories(dir);

  // 1. replay the route under the condition, with the benchmark camera and the trial's seed
  const fs::path override_file = dir / "override.yaml";
  WriteText(override_file, "# written by penumbra benchmark for job " + job.id +
                               "\nseed: " + std::to_string(job.seed) +
                               "\nmjcf_cameras: {enabled: false}\ncameras:\n  - " +
                               world.camera_yaml + "\n");
  auto t0 = std::chrono::steady_clock::now();
  ReplayOptions replay;
  replay.log_path = RecordingPath(context.out_dir, world);
  replay.out_dir = (dir / "replay").string();
  replay.force = true;
  replay.adversity = condition.adversity;
  replay.world_override = override_file.string();
  replay.tier = spec.tier == "pathtraced" ? RenderSettings::Tier::kPathtraced
                                          : RenderSettings::Tier::kRealtime;
  replay.threads = spec.render_threads;
  if (!context.backend.empty()) replay.backend = RenderSettings::BackendFromName(context.backend);
  replay.cameras = {world.camera_name};
  replay.progress = false;
  replay.stop_request = context.stop_request;
  const ReplaySummary replayed = ReplayLog(replay);
  if (replayed.interrupted) throw JobInterrupted("job " + job.id + " interrupted in its replay");
  const double replay_sec = Since(t0);

  // 2. export the datasets the methods read
  t0 = std::chrono::steady_clock::now();
  const RunFolder run(replay.out_dir);
  const RunCamera camera = run.ReadCamera(world.camera_name);
  std::map<std::string, DatasetExportSummary> exported;
  for (const BenchmarkMethod& m : spec.methods) {
    if (exported.count(m.dataset)) continue;
    DatasetExportOptions ex;
    ex.format = ParseDatasetFormat(m.dataset);
    ex.out_dir = dir / ("dataset_" + m.dataset);
    ex.camera = world.camera_name;
    ex.source_label =
        replay.log_path + " (" + condition.name + ", seed " + std::to_string(job.seed) + ")";
    exported[m.dataset] = ExportDataset(run, ex);
  }
  fs::copy_file(fs::path(replay.out_dir) / "camera_info.json", dir / "camera_info.json",
                fs::copy_options::overwrite_existing);
  // the ground truth: the camera's optical frame, as the TUM export writes it
  Trajectory gt;
  for (const RunFrame& f : camera.frames) {
    gt.time_sec.push_back(f.time_sec);
    gt.X_WB.push_back(f.X_WO);
  }
  const fs::path gt_file = dir / "groundtruth.txt";
  WriteText(gt_file, FormatTumTrajectory(gt));
  const double export_sec = Since(t0);

  // 3. every method, then its evaluation
  std::vector<BenchmarkRow> rows;
  for (const BenchmarkMethod& m : spec.methods) {
    BenchmarkRow row;
    row.world = world.name;
    row.condition = condition.name;
    row.method = m.name;
    row.trial = static_cast<int>(job.trial + 1);
    row.seed = job.seed;
    row.frames = static_cast<int64_t>(camera.frames.size());
    row.replay_sec = replay_sec;
    row.export_sec = export_sec;
    const fs::path workdir = dir / m.name;
    fs::create_directories(workdir);
    const fs::path dataset = dir / ("dataset_" + m.dataset);
    // values are plain text inside their words: never read by a shell
    const std::map<std::string, std::string> values = {
        {"penumbra", context.penumbra_binary},
        {"dataset", fs::absolute(dataset).string()},
        {"output", fs::absolute(workdir / "trajectory.txt").string()},
        {"workdir", fs::absolute(workdir).string()},
        {"fx", FormatNumber(camera.fx)},
        {"fy", FormatNumber(camera.fy)},
        {"cx", FormatNumber(camera.cx)},
        {"cy", FormatNumber(camera.cy)},
        {"width", std::to_string(camera.width)},
        {"height", std::to_string(camera.height)},
        {"camera_info", fs::absolute(dir / "camera_info.json").string()},
        {"seed", std::to_string(job.seed)}};
    const std::vector<std::string> argv = ExpandCommandTemplate(m.command_words, values);
    WriteText(workdir / "command.sh", MethodCommandScript(argv, fs::absolute(workdir).string()));
    const ProcessOutcome outcome =
        RunMethodCommand(argv, workdir.string(), m.timeout_sec, context.stop_request);
    if (outcome.stopped)
      throw JobInterrupted("job " + job.id + " interrupted while method " + m.name + " ran");
    row.method_sec = outcome.wall_sec;
    row.detail = outcome.Describe();
    const fs::path traj = workdir / m.trajectory;
    t0 = std::chrono::steady_clock::now();
    std::error_code ec;
    if (outcome.timed_out) {
      row.status = "timeout";
    } else if (!outcome.ok()) {
      row.status = "failed";
    } else if (!fs::is_regular_file(traj, ec)) {
      row.status = "no_output";
      row.detail += "; no trajectory file " + m.trajectory;
    } else {
      Trajectory est;
      try {
        est = ReadEstimate(traj, m.format);
        row.poses = static_cast<int64_t>(est.size());
        WriteText(workdir / "estimate.txt", FormatTumTrajectory(est));
      } catch (const ConfigError& e) {
        row.status = "bad_output";
        row.detail += std::string("; ") + e.what();
      }
      if (row.status.empty()) {
        try {
          Evaluate(gt, est, spec, m, gt_file.string(), traj.string(), row);
          row.status = "ok";
        } catch (const ConfigError& e) {
          row.status = "lost";
          row.detail += std::string("; ") + e.what();
        }
      }
    }
    row.eval_sec = Since(t0);
    rows.push_back(row);
  }
  if (!spec.keep_datasets) {
    fs::remove_all(replay.out_dir);
    for (const auto& [format, summary] : exported) fs::remove_all(dir / ("dataset_" + format));
  }
  nlohmann::json j = nlohmann::json::array();
  for (const BenchmarkRow& r : rows) j.push_back(RowJson(r));
  // written last and atomically (WriteText): its presence marks the job finished
  WriteText(JobResultPath(context.out_dir, job), j.dump(1) + "\n");
  return rows;
}

std::vector<BenchmarkRow> ReadJobResult(const std::string& path) {
  std::vector<BenchmarkRow> rows;
  try {
    const nlohmann::json j = nlohmann::json::parse(ReadText(path));
    for (const nlohmann::json& e : j) {
      BenchmarkRow r;
      r.world = e.at("world");
      r.condition = e.at("condition");
      r.method = e.at("method");
      r.trial = e.at("trial");
      r.seed = e.at("seed");
      r.status = e.at("status");
      r.detail = e.at("detail");
      r.frames = e.at("frames");
      r.poses = e.at("poses");
      r.ate_rmse_m = NumOf(e.at("ate_rmse_m"));
      r.ate_mean_m = NumOf(e.at("ate_mean_m"));
      r.ate_max_m = NumOf(e.at("ate_max_m"));
      r.rpe_trans_rmse_m = NumOf(e.at("rpe_trans_rmse_m"));
      r.rpe_rot_rmse_deg = NumOf(e.at("rpe_rot_rmse_deg"));
      r.coverage = NumOf(e.at("coverage"));
      r.scaled_ate_m = NumOf(e.at("scaled_ate_m"));
      r.tracked_fraction = NumOf(e.at("tracked_fraction"));
      // absent from job results written before these figures existed
      r.tracked_path_coverage = NumOf(e.value("tracked_path_coverage", nlohmann::json()));
      r.tracked_scaled_ate_m = NumOf(e.value("tracked_scaled_ate_m", nlohmann::json()));
      r.pose_fraction = NumOf(e.value("pose_fraction", nlohmann::json()));
      r.scale = NumOf(e.at("scale"));
      r.replay_sec = e.at("replay_sec");
      r.export_sec = e.at("export_sec");
      r.method_sec = e.at("method_sec");
      r.eval_sec = e.at("eval_sec");
      rows.push_back(r);
    }
  } catch (const nlohmann::json::exception& e) {
    throw ConfigError(path, 0, "", std::string("not a job result: ") + e.what());
  }
  return rows;
}

}  // namespace penumbra
