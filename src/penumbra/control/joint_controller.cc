#include "penumbra/control/joint_controller.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "penumbra/control/param_limits.h"
#include "penumbra/core/error.h"

namespace penumbra {
namespace {

const char* ModeKey(JointCommand::Mode m) {
  switch (m) {
    case JointCommand::Mode::kPosition:
      return "q";
    case JointCommand::Mode::kVelocity:
      return "qd";
    case JointCommand::Mode::kEffort:
      return "tau";
  }
  return "q";
}

}  // namespace

JointPdParams JointPdParams::Parse(ControllerParams& p, const std::string& prefix) {
  JointPdParams j;
  j.servo = JointServoParams::Parse(p, prefix, 400, 40, 2.0, 10.0);
  const size_t n = j.servo.joints.size();
  j.target = ReadOptionalNumbers(p, "target", n, -kMaxParamJointValue, kMaxParamJointValue,
                                 "rad or m, one per joint");
  j.commands = ParseCommandScript<JointCommand>(p, "commands", [n](ParamNode& item) {
    JointCommand c;
    int found = 0;
    for (auto mode : {JointCommand::Mode::kPosition, JointCommand::Mode::kVelocity,
                      JointCommand::Mode::kEffort}) {
      if (!item.Has(ModeKey(mode))) continue;
      ++found;
      c.mode = mode;
      const double bound = mode == JointCommand::Mode::kPosition   ? kMaxParamJointValue
                           : mode == JointCommand::Mode::kVelocity ? kMaxParamJointVelocity
                                                                   : kMaxParamEffort;
      c.values = item.Numbers(ModeKey(mode), n, -bound, bound, "one per joint");
    }
    if (found != 1)
      item.FailHere(std::string(found ? "got more than one of" : "missing") +
                    " q / qd / tau; expected exactly one: q (position target), qd (velocity) "
                    "or tau (effort)");
    return c;
  });
  j.rate_hz = p.Number("rate_hz", 0, 0, kMaxParamRateHz);
  p.CheckNoUnknownKeys();
  return j;
}

void JointPdParams::ValidateOrThrow(const ControllerContext& c) const {
  servo.ValidateOrThrow(c);
  auto fail = [&](const std::string& key, const std::string& problem) {
    throw ConfigError(c.file, c.line, c.key.empty() ? key : c.key + "." + key, problem);
  };
  const size_t n = servo.joints.size();
  if (target && target->size() != n)
    fail("target", "got " + std::to_string(target->size()) + " values; expected " +
                       std::to_string(n) + " (one per joint)");
  for (size_t i = 0; i < commands.size(); ++i) {
    const JointCommand& cmd = commands[i].command;
    const std::string key = "commands[" + std::to_string(i) + "]";
    if (cmd.values.size() != n)
      fail(key + "." + ModeKey(cmd.mode),
           "got " + std::to_string(cmd.values.size()) + " values; expected " + std::to_string(n));
    if (cmd.mode == JointCommand::Mode::kEffort && servo.output == ServoOutput::kPosition)
      fail(key + ".tau",
           "effort commands need output: torque; expected q or qd with output: position");
  }
  if (!(std::isfinite(rate_hz) && rate_hz >= 0))
    fail("rate_hz", "got " + std::to_string(rate_hz) + "; expected a number >= 0");
}

JointPdController::JointPdController(JointPdParams params, ControllerContext context)
    : Controller(std::move(context)),
      params_(std::move(params)),
      servo_(params_.servo, this->context()),
      commands_(params_.commands) {
  params_.ValidateOrThrow(this->context());
}

std::vector<NameRequirement> JointPdController::RequiredNames() const {
  std::vector<NameRequirement> reqs;
  servo_.AppendRequiredNames(&reqs);
  return reqs;
}

void JointPdController::OnInitialize(const ModelInfo& model, const std::vector<int>& ids) {
  servo_.Bind(model, ids, context());
  Reset();
}

void JointPdController::CheckCommand(const JointCommand& c) const {
  const size_t n = params_.servo.joints.size();
  if (c.values.size() != n)
    throw Error(label() + ": command with " + std::to_string(c.values.size()) +
                " values; expected " + std::to_string(n) + " (one per joint)");
  for (double v : c.values)
    if (!std::isfinite(v)) throw Error(label() + ": command with a non-finite value");
  if (c.mode == JointCommand::Mode::kEffort && params_.servo.output == ServoOutput::kPosition)
    throw Error(label() + ": effort command, but the output is position");
}

void JointPdController::PushCommand(JointCommand command, double at_time_sec) {
  CheckCommand(command);
  commands_.Push(std::move(command), at_time_sec);
}

void JointPdController::SetCommand(JointCommand command) {
  CheckCommand(command);
  commands_.Set(std::move(command));
}

void JointPdController::Apply(const JointCommand& c, const Eigen::VectorXd& q) {
  // leaving effort mode: the reference restarts where the joints are
  if (active_.mode == JointCommand::Mode::kEffort && c.mode != JointCommand::Mode::kEffort)
    q_ref_ = servo_.ClampPosition(q);
  active_ = c;
  values_ = Eigen::Map<const Eigen::VectorXd>(c.values.data(), c.values.size());
  if (c.mode == JointCommand::Mode::kPosition) target_ = servo_.ClampPosition(values_);
}

void JointPdController::Reset() {
  commands_.ClearQueue();
  commands_.Rewind();
  active_ = JointCommand{};
  started_ = false;
  last_time_ = 0;
  q_ref_.resize(0);
  qd_ref_.resize(0);
  target_.resize(0);
  values_.resize(0);
}

void JointPdController::Compute(const ControlInput& input, std::span<double> ctrl) {
  const double t = input.time_sec();
  servo_.ReadState(input, &q_, &qd_);
  const int n = servo_.size();
  if (!started_) {
    started_ = true;
    last_time_ = t;
    q_ref_ = servo_.ClampPosition(q_);
    qd_ref_ = Eigen::VectorXd::Zero(n);
    target_ =
        params_.target
            ? servo_.ClampPosition(Eigen::Map<const Eigen::VectorXd>(params_.target->data(), n))
            : q_ref_;
    active_ = JointCommand::Position(std::vector<double>(target_.data(), target_.data() + n));
  }
  const double dt = std::max(0.0, t - last_time_);
  last_time_ = t;
  // a velocity reference integrates over (t - dt, t] the velocity that was commanded then
  if (active_.mode == JointCommand::Mode::kVelocity) {
    for (int i = 0; i < n; ++i) {
      const double v = std::clamp(values_[i], -servo_.qd_max()[i], servo_.qd_max()[i]);
      q_ref_[i] = std::clamp(q_ref_[i] + v * dt, servo_.q_min()[i], servo_.q_max()[i]);
    }
  }
  commands_.Poll(t, [&](const JointCommand& c) { Apply(c, q_); });

  switch (active_.mode) {
    case JointCommand::Mode::kPosition:
      servo_.StepTowards(target_, {}, dt, &q_ref_, &qd_ref_);
      servo_.Write(input, q_ref_, qd_ref_, {}, ctrl);
      break;
    case JointCommand::Mode::kVelocity:
      // feed-forward the commanded velocity, except where the reference sits at a bound
      // and the command pushes outwards
      for (int i = 0; i < n; ++i) {
        const double v = std::clamp(values_[i], -servo_.qd_max()[i], servo_.qd_max()[i]);
        const bool stopped =
            (v > 0 && q_ref_[i] >= servo_.q_max()[i]) || (v < 0 && q_ref_[i] <= servo_.q_min()[i]);
        qd_ref_[i] = stopped ? 0 : v;
      }
      servo_.Write(input, q_ref_, qd_ref_, {}, ctrl);
      break;
    case JointCommand::Mode::kEffort:
      q_ref_ = q_;
      qd_ref_ = qd_;
      servo_.WriteEffort(input, values_, ctrl);
      break;
  }
}

}  // namespace penumbra
