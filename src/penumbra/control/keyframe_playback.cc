#include "penumbra/control/keyframe_playback.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <sstream>

#include "penumbra/config/config_value.h"
#include "penumbra/control/command_script.h"
#include "penumbra/control/param_limits.h"
#include "penumbra/control/param_mapping.h"
#include "penumbra/control/param_node.h"
#include "penumbra/core/error.h"
#include "penumbra/core/input_file.h"

namespace penumbra {
namespace {

std::string Trim(const std::string& s) {
  const size_t a = s.find_first_not_of(" \t\r");
  if (a == std::string::npos) return "";
  const size_t b = s.find_last_not_of(" \t\r");
  return s.substr(a, b - a + 1);
}

std::vector<std::string> SplitCsv(const std::string& line) {
  std::vector<std::string> out;
  std::stringstream s(line);
  std::string cell;
  while (std::getline(s, cell, ',')) out.push_back(Trim(cell));
  if (!line.empty() && line.back() == ',') out.push_back("");
  return out;
}

std::string LocalName(const std::string& full, const std::string& prefix) {
  return full.rfind(prefix, 0) == 0 ? full.substr(prefix.size()) : full;
}

}  // namespace

std::vector<PlaybackFrame> ReadJointCsv(const std::string& path,
                                        const std::vector<std::string>& columns,
                                        const std::string& gripper_column) {
  // read whole as a regular file: a FIFO named in a world file would block open() for ever
  std::istringstream in(ReadInputFile(path, "CSV file"));
  std::string line;
  int line_no = 0;
  std::vector<std::string> header;
  // header: the first line that is neither blank nor a comment
  while (std::getline(in, line)) {
    ++line_no;
    const std::string t = Trim(line);
    if (t.empty() || t[0] == '#') continue;
    header = SplitCsv(t);
    break;
  }
  std::string expected_header = "time_sec";
  for (const auto& c : columns) expected_header += "," + c;
  if (!gripper_column.empty()) expected_header += "," + gripper_column;
  if (header.empty())
    throw ConfigError(path, line_no, "", "no header line; expected '" + expected_header + "'");
  if (header[0] != "time_sec")
    throw ConfigError(path, line_no, "",
                      "first column is '" + header[0] + "'; expected time_sec (header '" +
                          expected_header + "', joint columns in any order)");
  // column index of every joint (and the gripper)
  std::vector<std::string> wanted = columns;
  if (!gripper_column.empty()) wanted.push_back(gripper_column);
  std::vector<int> col(wanted.size(), -1);
  std::string unknown;
  for (size_t h = 1; h < header.size(); ++h) {
    bool found = false;
    for (size_t k = 0; k < wanted.size(); ++k)
      if (header[h] == wanted[k]) {
        if (col[k] >= 0)
          throw ConfigError(path, line_no, "", "column '" + header[h] + "' appears twice");
        col[k] = static_cast<int>(h);
        found = true;
      }
    if (!found) unknown += (unknown.empty() ? "'" : ", '") + header[h] + "'";
  }
  std::string missing;
  for (size_t k = 0; k < wanted.size(); ++k)
    if (col[k] < 0) missing += (missing.empty() ? "'" : ", '") + wanted[k] + "'";
  if (!missing.empty() || !unknown.empty())
    throw ConfigError(path, line_no, "",
                      (missing.empty() ? "" : "missing column(s) " + missing) +
                          (missing.empty() || unknown.empty() ? "" : "; ") +
                          (unknown.empty() ? "" : "unknown column(s) " + unknown) +
                          "; expected the header '" + expected_header +
                          "' (joint columns in any order)");
  std::vector<PlaybackFrame> frames;
  while (std::getline(in, line)) {
    ++line_no;
    const std::string t = Trim(line);
    if (t.empty() || t[0] == '#') continue;
    const std::vector<std::string> cells = SplitCsv(t);
    if (cells.size() != header.size())
      throw ConfigError(path, line_no, "",
                        "got " + std::to_string(cells.size()) + " values; expected " +
                            std::to_string(header.size()) + " (one per header column)");
    std::vector<double> v(cells.size());
    for (size_t c = 0; c < cells.size(); ++c) {
      size_t used = 0;
      bool ok = !cells[c].empty();
      try {
        if (ok) v[c] = std::stod(cells[c], &used);
      } catch (const std::exception&) {
        ok = false;
      }
      if (!ok || used != cells[c].size() || !std::isfinite(v[c]))
        throw ConfigError(
            path, line_no, "",
            "column '" + header[c] + "': got '" + cells[c] + "'; expected a finite number");
    }
    PlaybackFrame f;
    f.time_sec = v[0];
    if (f.time_sec < 0 || f.time_sec > kMaxParamTimeSec)
      throw ConfigError(path, line_no, "",
                        "time_sec " + cells[0] + " is out of range; expected a time in [0, " +
                            param::FormatNumber(kMaxParamTimeSec) + "] (s)");
    for (size_t c = 1; c < v.size(); ++c)
      if (std::abs(v[c]) > kMaxParamJointValue)
        throw ConfigError(path, line_no, "",
                          "column '" + header[c] + "': got " + cells[c] +
                              "; expected a joint value in [-" +
                              param::FormatNumber(kMaxParamJointValue) + ", " +
                              param::FormatNumber(kMaxParamJointValue) + "] (rad or m)");
    if (!frames.empty() && f.time_sec <= frames.back().time_sec)
      throw ConfigError(path, line_no, "",
                        "time_sec does not increase; expected strictly increasing times");
    for (size_t k = 0; k < columns.size(); ++k) f.q.push_back(v[col[k]]);
    if (!gripper_column.empty()) f.gripper = v[col.back()];
    frames.push_back(std::move(f));
  }
  if (frames.empty())
    throw ConfigError(path, line_no, "", "no data rows; expected at least one row of targets");
  return frames;
}

KeyframePlaybackParams KeyframePlaybackParams::Parse(ControllerParams& p,
                                                     const std::string& prefix) {
  KeyframePlaybackParams k;
  k.servo = JointServoParams::Parse(p, prefix, 400, 40, 2.0, 10.0);
  const size_t n = k.servo.joints.size();
  if (p.Has("gripper_actuator") || p.Has("gripper_joint")) {
    k.gripper_actuator = prefix + p.String("gripper_actuator");
    k.gripper_joint = prefix + p.String("gripper_joint");
  } else {
    p.Raw("gripper_actuator");
    p.Raw("gripper_joint");
  }
  const bool gripper = !k.gripper_actuator.empty();
  const bool has_frames = p.Has("frames"), has_csv = p.Has("csv");
  if (has_frames == has_csv)
    p.Fail(has_frames ? "csv" : "frames",
           has_frames ? "given together with frames; expected exactly one of frames and csv"
                      : "missing; expected exactly one of frames (a list of {t, key or q}) and "
                        "csv (a file of joint targets)");
  if (has_csv) {
    p.Raw("frames");
    std::filesystem::path path = p.String("csv");
    if (path.is_relative() && !p.context().file.empty())
      path = std::filesystem::path(p.context().file).parent_path() / path;
    k.csv_path = path.lexically_normal().string();
    std::vector<std::string> columns;
    for (const auto& j : k.servo.joints) columns.push_back(LocalName(j, prefix));
    k.frames = ReadJointCsv(k.csv_path, columns,
                            gripper ? LocalName(k.gripper_joint, prefix) : std::string());
  } else {
    p.Raw("csv");
    auto items = ParseCommandScript<PlaybackFrame>(p, "frames", [&](ParamNode& item) {
      PlaybackFrame f;
      if (item.Has("key") == item.Has("q"))
        item.FailHere(item.Has("key") ? "has both key and q; expected one of them"
                                      : "missing key or q; expected an MJCF key name or joint "
                                        "values (one per joint)");
      if (item.Has("key")) {
        f.key = prefix + item.String("key");
        item.Raw("q");
      } else {
        f.q = item.Numbers("q", n, -kMaxParamJointValue, kMaxParamJointValue,
                           "rad or m, one per joint");
        item.Raw("key");
      }
      if (item.Has("gripper")) {
        if (!gripper) item.Fail("gripper", "given without gripper_actuator/gripper_joint");
        f.gripper = item.Number("gripper", std::nullopt, -kMaxParamJointValue, kMaxParamJointValue);
      } else if (gripper && f.key.empty()) {
        item.Fail("gripper",
                  "missing; expected the gripper_joint value (m or rad) for a q frame "
                  "when gripper_actuator is set");
      } else {
        item.Raw("gripper");
      }
      return f;
    });
    if (items.empty()) p.Fail("frames", "empty; expected at least one frame");
    for (size_t i = 0; i < items.size(); ++i) {
      if (i > 0 && items[i].time_sec <= items[i - 1].time_sec)
        p.Fail("frames[" + std::to_string(i) + "].t",
               "equal to the previous frame's time; expected strictly increasing times");
      items[i].command.time_sec = items[i].time_sec;
      k.frames.push_back(std::move(items[i].command));
    }
  }
  k.loop = p.Bool("loop", false);
  k.rate_hz = p.Number("rate_hz", 0, 0, kMaxParamRateHz);
  p.CheckNoUnknownKeys();
  return k;
}

void KeyframePlaybackParams::ValidateOrThrow(const ControllerContext& c) const {
  servo.ValidateOrThrow(c);
  auto fail = [&](const std::string& key, const std::string& problem) {
    throw ConfigError(c.file, c.line, c.key.empty() ? key : c.key + "." + key, problem);
  };
  if (frames.empty()) fail("frames", "empty; expected at least one frame");
  if (gripper_actuator.empty() != gripper_joint.empty())
    fail("gripper_joint", "expected gripper_actuator and gripper_joint together");
  for (size_t i = 0; i < frames.size(); ++i) {
    const PlaybackFrame& f = frames[i];
    const std::string key = "frames[" + std::to_string(i) + "]";
    if (!(std::isfinite(f.time_sec) && f.time_sec >= 0))
      fail(key + ".t", "expected a time >= 0 (s)");
    if (i > 0 && f.time_sec <= frames[i - 1].time_sec)
      fail(key + ".t", "expected strictly increasing times");
    if (f.key.empty() && f.q.size() != servo.joints.size())
      fail(key + ".q", "got " + std::to_string(f.q.size()) + " values; expected " +
                           std::to_string(servo.joints.size()));
    if (!gripper_actuator.empty() && f.key.empty() && !f.gripper)
      fail(key + ".gripper", "missing; expected the gripper_joint value");
  }
  if (!(std::isfinite(rate_hz) && rate_hz >= 0)) fail("rate_hz", "expected a number >= 0");
}

KeyframePlayback::KeyframePlayback(KeyframePlaybackParams params, ControllerContext context)
    : Controller(std::move(context)),
      params_(std::move(params)),
      servo_(params_.servo, this->context()) {
  params_.ValidateOrThrow(this->context());
}

std::vector<NameRequirement> KeyframePlayback::RequiredNames() const {
  std::vector<NameRequirement> reqs;
  servo_.AppendRequiredNames(&reqs);
  for (size_t i = 0; i < params_.frames.size(); ++i)
    if (!params_.frames[i].key.empty())
      reqs.push_back(
          {ModelObject::kKey, params_.frames[i].key, "frames[" + std::to_string(i) + "].key"});
  if (!params_.gripper_actuator.empty()) {
    reqs.push_back({ModelObject::kActuator, params_.gripper_actuator, "gripper_actuator"});
    reqs.push_back({ModelObject::kJoint, params_.gripper_joint, "gripper_joint"});
  }
  return reqs;
}

void KeyframePlayback::Reset() {
  const int n = servo_.size();
  started_ = finished_ = false;
  start_time_ = last_time_ = gripper_start_ = 0;
  q_start_.setZero(n);
  target_.setZero(n);
  target_velocity_.setZero(n);
  q_ref_.setZero(n);
  qd_ref_.setZero(n);
}

void KeyframePlayback::OnInitialize(const ModelInfo& model, const std::vector<int>& ids) {
  const int n = servo_.size();
  servo_.Bind(model, std::span<const int>(ids.data(), 2 * n), context());
  size_t k = 2 * n;
  std::vector<int> key_ids;
  for (const auto& f : params_.frames)
    if (!f.key.empty()) key_ids.push_back(ids[k++]);
  gripper_actuator_ = gripper_qpos_adr_ = -1;
  if (!params_.gripper_actuator.empty()) {
    gripper_actuator_ = ids[k++];
    const JointInfo& gj = model.joints[ids[k++]];
    if (gj.type != JointInfo::Type::kHinge && gj.type != JointInfo::Type::kSlide)
      throw ConfigError(
          context().file, context().line, context().key + ".gripper_joint",
          "joint '" + gj.name + "' is a free or ball joint; expected a hinge or slide");
    gripper_qpos_adr_ = gj.qpos_adr;
  }
  times_.clear();
  qs_.clear();
  grippers_.clear();
  size_t next_key = 0;
  for (const auto& f : params_.frames) {
    Eigen::VectorXd q(n);
    double g = 0;
    if (!f.key.empty()) {
      const KeyInfo& key = model.keys[key_ids[next_key++]];
      if (static_cast<int>(key.qpos.size()) != model.nq)
        throw ConfigError(context().file, context().line, context().key + ".frames",
                          "keyframe '" + key.name + "' has " + std::to_string(key.qpos.size()) +
                              " qpos values; expected nq = " + std::to_string(model.nq));
      for (int i = 0; i < n; ++i) q[i] = key.qpos[model.joints[ids[i]].qpos_adr];
      if (gripper_qpos_adr_ >= 0) g = key.qpos[gripper_qpos_adr_];
    } else {
      for (int i = 0; i < n; ++i) q[i] = f.q[i];
    }
    if (f.gripper) g = *f.gripper;
    times_.push_back(f.time_sec);
    qs_.push_back(q);
    grippers_.push_back(g);
  }
  Reset();
}

void KeyframePlayback::Evaluate(double t_rel, const Eigen::VectorXd& q_start, double gripper_start,
                                Eigen::VectorXd* q, Eigen::VectorXd* qd, double* gripper) const {
  const double t_last = times_.back();
  const Eigen::VectorXd* first_from = &q_start;
  double g_from = gripper_start;
  double t = t_rel;
  if (params_.loop && t_last > 0 && t >= t_last) {
    // later laps: the segment before the first frame starts from the last frame
    t = std::fmod(t, t_last);
    first_from = &qs_.back();
    g_from = grippers_.back();
  }
  if (t <= times_[0]) {
    if (times_[0] <= 0) {
      *q = qs_[0];
      qd->setZero(q->size());
      *gripper = grippers_[0];
    } else {
      const double a = std::max(0.0, t) / times_[0];
      *q = *first_from + a * (qs_[0] - *first_from);
      *qd = (qs_[0] - *first_from) / times_[0];
      *gripper = g_from + a * (grippers_[0] - g_from);
    }
    return;
  }
  if (t >= t_last) {
    *q = qs_.back();
    qd->setZero(q->size());
    *gripper = grippers_.back();
    return;
  }
  const size_t i =
      static_cast<size_t>(std::upper_bound(times_.begin(), times_.end(), t) - times_.begin()) - 1;
  const double a = (t - times_[i]) / (times_[i + 1] - times_[i]);
  *q = qs_[i] + a * (qs_[i + 1] - qs_[i]);
  *qd = (qs_[i + 1] - qs_[i]) / (times_[i + 1] - times_[i]);
  *gripper = grippers_[i] + a * (grippers_[i + 1] - grippers_[i]);
}

void KeyframePlayback::Compute(const ControlInput& input, std::span<double> ctrl) {
  const double t = input.time_sec();
  servo_.ReadState(input, &q_, &qd_);
  if (!started_) {
    started_ = true;
    start_time_ = last_time_ = t;
    q_start_ = q_;
    q_ref_ = servo_.ClampPosition(q_);
    gripper_start_ = gripper_qpos_adr_ >= 0 ? input.qpos()[gripper_qpos_adr_] : 0;
  }
  const double dt = std::max(0.0, t - last_time_);
  last_time_ = t;
  const double t_rel = t - start_time_;
  double gripper = 0;
  Evaluate(t_rel, q_start_, gripper_start_, &target_, &target_velocity_, &gripper);
  finished_ = !params_.loop && t_rel >= times_.back();

  servo_.StepTowards(target_, target_velocity_, dt, &q_ref_, &qd_ref_);
  servo_.Write(input, q_ref_, qd_ref_, {}, ctrl);
  if (gripper_actuator_ >= 0) ctrl[gripper_actuator_] = gripper;
}

}  // namespace penumbra
