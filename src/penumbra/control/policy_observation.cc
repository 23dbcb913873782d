#include "penumbra/control/policy_observation.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <set>

#include "penumbra/config/config_value.h"
#include "penumbra/core/error.h"

namespace penumbra {
namespace {

struct TermName {
  ObservationTermKind kind;
  const char* name;
};

// the closed set of terms, in enum order
constexpr TermName kTermNames[] = {
    {ObservationTermKind::kBaseLinVel, "base_lin_vel"},
    {ObservationTermKind::kBaseAngVel, "base_ang_vel"},
    {ObservationTermKind::kProjectedGravity, "projected_gravity"},
    {ObservationTermKind::kVelocityCommand, "velocity_command"},
    {ObservationTermKind::kJointPos, "joint_pos"},
    {ObservationTermKind::kJointVel, "joint_vel"},
    {ObservationTermKind::kLastAction, "last_action"},
    {ObservationTermKind::kHeightScan, "height_scan"},
    {ObservationTermKind::kContact, "contact"},
    {ObservationTermKind::kPhase, "phase"},
    {ObservationTermKind::kSensor, "sensor"},
};

std::string ObsName(ControllerParams& p, const ConfigValue& n, const std::string& key) {
  if (!n.IsScalar() || n.Scalar().empty())
    p.Fail(key, "got " + DescribeParamNode(n) + "; expected a name");
  return n.Scalar();
}

// 64-bit draw -> uniform double in [-1, 1) (53 bits)
double SignedUniform(std::mt19937_64& rng) {
  const double u = static_cast<double>(rng() >> 11) * (1.0 / 9007199254740992.0);
  return 2.0 * u - 1.0;
}

}  // namespace

const char* ObservationTermName(ObservationTermKind kind) {
  for (const TermName& t : kTermNames)
    if (t.kind == kind) return t.name;
  return "?";
}

std::optional<ObservationTermKind> ObservationTermFromName(const std::string& name) {
  for (const TermName& t : kTermNames)
    if (name == t.name) return t.kind;
  return std::nullopt;
}

std::string ObservationTermNames() {
  std::string s;
  for (const TermName& t : kTermNames) s += (s.empty() ? "" : ", ") + std::string(t.name);
  return s;
}

int HeightScanGrid::nx() const {
  return static_cast<int>(std::floor(size_x_m / resolution_m + 1e-9)) + 1;
}
int HeightScanGrid::ny() const {
  return static_cast<int>(std::floor(size_y_m / resolution_m + 1e-9)) + 1;
}

ObservationTermConfig ObservationTermConfig::Parse(ControllerParams& p, const ConfigValue& n,
                                                   const std::string& key,
                                                   const std::string& prefix) {
  const std::string expected_term =
      "expected {term: <" + ObservationTermNames() + ">, scale, clip, noise, history, ...}";
  if (!n.IsMap()) p.Fail(key, "got " + DescribeParamNode(n) + "; " + expected_term);
  if (!n["term"]) p.Fail(key + ".term", "missing; " + expected_term);
  const std::string name = ObsName(p, n["term"], key + ".term");
  const auto kind = ObservationTermFromName(name);
  if (!kind)
    p.Fail(key + ".term",
           "unknown term '" + name + "'; expected one of: " + ObservationTermNames());
  ObservationTermConfig t;
  t.kind = *kind;

  // the fields every term takes, plus its own
  std::set<std::string> allowed = {"term", "scale", "clip", "noise", "history"};
  switch (t.kind) {
    case ObservationTermKind::kHeightScan:
      allowed.insert({"size_m", "resolution_m", "offset_m", "start_m", "max_distance_m", "order"});
      break;
    case ObservationTermKind::kContact:
      allowed.insert({"sensors", "threshold_n"});
      break;
    case ObservationTermKind::kPhase:
      allowed.insert("period_sec");
      break;
    case ObservationTermKind::kSensor:
      allowed.insert("name");
      break;
    default:
      break;
  }
  for (const auto& kv : n.pairs()) {
    const std::string k = kv.first.Scalar();
    if (!allowed.count(k)) {
      std::string list;
      for (const auto& a : allowed) list += (list.empty() ? "" : ", ") + a;
      p.Fail(key + "." + k, "unknown field for term '" + name + "'; expected only " + list);
    }
  }

  if (n["scale"])
    t.scale = ParamNumbersAt(p, n["scale"], key + ".scale", "a number with |scale| <= 1e4",
                             [](double v) { return std::abs(v) <= kObservationMaxScale; });
  if (n["clip"]) {
    const double c = ParamNumberAt(p, n["clip"], key + ".clip", "a number in (0, 1e6]");
    if (!(c > 0) || c > 1e6)
      p.Fail(key + ".clip", "got " + n["clip"].Scalar() + "; expected a number in (0, 1e6]");
    t.clip = c;
  }
  if (n["noise"])
    t.noise = ParamNumbersAt(p, n["noise"], key + ".noise", "a half-width in [0, 1e6]",
                             [](double v) { return v >= 0 && v <= 1e6; });
  if (n["history"]) {
    const double h = ParamNumberAt(p, n["history"], key + ".history", "an integer >= 1");
    if (!(h >= 1 && h <= 1000 && h == std::floor(h)))
      p.Fail(key + ".history", "got " + n["history"].Scalar() + "; expected an integer 1 .. 1000");
    t.history = static_cast<int>(h);
  }

  switch (t.kind) {
    case ObservationTermKind::kHeightScan: {
      HeightScanGrid& g = t.grid;
      if (n["size_m"]) {
        const ConfigValue s = n["size_m"];
        if (!s.IsSequence() || s.size() != 2)
          p.Fail(key + ".size_m",
                 "got " + DescribeParamNode(s) + "; expected [size_x, size_y] (m)");
        g.size_x_m = ParamNumberAt(p, s[0], key + ".size_m[0]", "a length >= 0 (m)");
        g.size_y_m = ParamNumberAt(p, s[1], key + ".size_m[1]", "a length >= 0 (m)");
        if (g.size_x_m < 0 || g.size_y_m < 0 || g.size_x_m > 100 || g.size_y_m > 100)
          p.Fail(key + ".size_m", "expected lengths 0 .. 100 m");
      }
      if (n["resolution_m"]) {
        g.resolution_m = ParamNumberAt(p, n["resolution_m"], key + ".resolution_m", "a length > 0");
        if (!(g.resolution_m > 0))
          p.Fail(key + ".resolution_m", "got " + n["resolution_m"].Scalar() + "; expected > 0");
      }
      if (static_cast<double>(g.nx()) * g.ny() > 100000)
        p.Fail(key + ".resolution_m", "the grid has " + std::to_string(g.nx()) + " x " +
                                          std::to_string(g.ny()) +
                                          " rays; expected at most 100000");
      if (n["offset_m"])
        g.offset_m = ParamNumberAt(p, n["offset_m"], key + ".offset_m", "a length (m)");
      if (n["start_m"]) {
        g.start_m = ParamNumberAt(p, n["start_m"], key + ".start_m", "a height > 0 (m)");
        if (!(g.start_m > 0)) p.Fail(key + ".start_m", "expected a height > 0 (m)");
      }
      if (n["max_distance_m"]) {
        g.max_distance_m =
            ParamNumberAt(p, n["max_distance_m"], key + ".max_distance_m", "a length > 0 (m)");
        if (!(g.max_distance_m > 0)) p.Fail(key + ".max_distance_m", "expected a length > 0 (m)");
      }
      if (n["order"]) {
        const std::string o = ObsName(p, n["order"], key + ".order");
        if (o != "xy" && o != "yx")
          p.Fail(key + ".order", "got '" + o + "'; expected xy (x fastest) or yx (y fastest)");
        g.x_fastest = o == "xy";
      }
      break;
    }
    case ObservationTermKind::kContact: {
      if (!n["sensors"] || !n["sensors"].IsSequence() || n["sensors"].size() == 0)
        p.Fail(key + ".sensors", "missing or empty; expected a list of MuJoCo touch sensor names");
      for (size_t i = 0; i < n["sensors"].size(); ++i)
        t.sensors.push_back(
            prefix + ObsName(p, n["sensors"][i], key + ".sensors[" + std::to_string(i) + "]"));
      if (n["threshold_n"])
        t.threshold_n = ParamNumberAt(p, n["threshold_n"], key + ".threshold_n", "a force (N)");
      break;
    }
    case ObservationTermKind::kPhase:
      if (!n["period_sec"]) p.Fail(key + ".period_sec", "missing; expected a period > 0 (s)");
      t.period_sec = ParamNumberAt(p, n["period_sec"], key + ".period_sec", "a period > 0 (s)");
      if (!(t.period_sec > 0)) p.Fail(key + ".period_sec", "expected a period > 0 (s)");
      break;
    case ObservationTermKind::kSensor:
      if (!n["name"]) p.Fail(key + ".name", "missing; expected a MuJoCo sensor name");
      t.sensors.push_back(prefix + ObsName(p, n["name"], key + ".name"));
      break;
    default:
      break;
  }
  return t;
}

PolicyObservation::PolicyObservation(std::vector<ObservationTermConfig> terms, uint64_t seed,
                                     const ControllerContext& context)
    : terms_(std::move(terms)), seed_(seed), context_(context), rng_(seed) {
  auto fail = [&](const std::string& key, const std::string& problem) {
    throw ConfigError(context_.file, context_.line,
                      context_.key.empty() ? key : context_.key + "." + key, problem);
  };
  if (terms_.empty()) fail("observations", "empty; expected at least one observation term");
  for (size_t i = 0; i < terms_.size(); ++i) {
    const ObservationTermConfig& t = terms_[i];
    const std::string key = "observations[" + std::to_string(i) + "]";
    if (t.scale.empty() || t.noise.empty()) fail(key, "expected a scale and a noise");
    for (double s : t.scale)
      if (!std::isfinite(s)) fail(key + ".scale", "expected finite numbers");
    for (double s : t.noise)
      if (!(s >= 0 && std::isfinite(s))) fail(key + ".noise", "expected half-widths >= 0");
    if (t.clip && !(*t.clip > 0)) fail(key + ".clip", "expected a number > 0");
    if (t.history < 1) fail(key + ".history", "expected an integer >= 1");
  }
}

void PolicyObservation::AppendRequiredNames(std::vector<NameRequirement>* reqs) const {
  for (size_t i = 0; i < terms_.size(); ++i) {
    const ObservationTermConfig& t = terms_[i];
    const std::string key = "observations[" + std::to_string(i) + "]";
    for (size_t k = 0; k < t.sensors.size(); ++k)
      reqs->push_back({ModelObject::kSensor, t.sensors[k],
                       t.kind == ObservationTermKind::kSensor
                           ? key + ".name"
                           : key + ".sensors[" + std::to_string(k) + "]"});
  }
}

bool PolicyObservation::needs_ray_caster() const {
  return std::any_of(terms_.begin(), terms_.end(), [](const ObservationTermConfig& t) {
    return t.kind == ObservationTermKind::kHeightScan;
  });
}

void PolicyObservation::Bind(const ModelInfo& model, int base_body, std::vector<int> joint_qpos,
                             std::vector<int> joint_dof, Eigen::VectorXd default_q, int action_size,
                             std::span<const int> sensor_ids) {
  auto fail = [&](const std::string& key, const std::string& problem) {
    throw ConfigError(context_.file, context_.line,
                      context_.key.empty() ? key : context_.key + "." + key, problem);
  };
  base_ = base_body;
  joint_qpos_ = std::move(joint_qpos);
  joint_dof_ = std::move(joint_dof);
  default_q_ = std::move(default_q);
  const int n = static_cast<int>(joint_qpos_.size());
  sensor_adr_.assign(terms_.size(), {});
  sensor_dim_.assign(terms_.size(), {});
  term_sizes_.assign(terms_.size(), 0);
  size_t next = 0;
  size_ = 0;
  for (size_t i = 0; i < terms_.size(); ++i) {
    const ObservationTermConfig& t = terms_[i];
    const std::string key = "observations[" + std::to_string(i) + "]";
    for (size_t k = 0; k < t.sensors.size(); ++k) {
      const SensorInfo& s = model.sensors[sensor_ids[next++]];
      if (t.kind == ObservationTermKind::kContact && s.dim != 1)
        fail(key + ".sensors[" + std::to_string(k) + "]",
             "sensor '" + s.name + "' has " + std::to_string(s.dim) +
                 " values; expected a 1-value touch sensor");
      sensor_adr_[i].push_back(s.adr);
      sensor_dim_[i].push_back(s.dim);
    }
    int dim = 0;
    switch (t.kind) {
      case ObservationTermKind::kBaseLinVel:
      case ObservationTermKind::kBaseAngVel:
      case ObservationTermKind::kProjectedGravity:
      case ObservationTermKind::kVelocityCommand:
        dim = 3;
        break;
      case ObservationTermKind::kJointPos:
      case ObservationTermKind::kJointVel:
        dim = n;
        break;
      case ObservationTermKind::kLastAction:
        dim = action_size;
        break;
      case ObservationTermKind::kHeightScan:
        dim = t.grid.nx() * t.grid.ny();
        break;
      case ObservationTermKind::kContact:
        dim = static_cast<int>(t.sensors.size());
        break;
      case ObservationTermKind::kPhase:
        dim = 2;
        break;
      case ObservationTermKind::kSensor:
        dim = sensor_dim_[i].empty() ? 0 : sensor_dim_[i][0];
        break;
    }
    for (const auto* list : {&t.scale, &t.noise})
      if (list->size() != 1 && static_cast<int>(list->size()) != dim)
        fail(key + (list == &t.scale ? ".scale" : ".noise"),
             "has " + std::to_string(list->size()) + " values; term '" +
                 ObservationTermName(t.kind) + "' has " + std::to_string(dim) +
                 " elements: expected 1 value or " + std::to_string(dim));
    term_sizes_[i] = dim;
    size_ += dim * t.history;
  }
  Reset();
}

void PolicyObservation::Reset() {
  history_.assign(terms_.size(), {});
  rng_.seed(seed_);
}

void PolicyObservation::RawTerm(int i, const ObservationContext& ctx, std::span<double> out) const {
  const ObservationTermConfig& t = terms_[i];
  const ControlInput& in = *ctx.input;
  const Pose X_WB = in.X_WB(base_);
  const Eigen::Matrix3d R = X_WB.linear();
  auto put3 = [&](const Eigen::Vector3d& v) {
    for (int k = 0; k < 3; ++k) out[k] = v[k];
  };
  switch (t.kind) {
    case ObservationTermKind::kBaseLinVel:
      put3(R.transpose() * in.V_WB(base_).tail<3>());
      break;
    case ObservationTermKind::kBaseAngVel:
      put3(R.transpose() * in.V_WB(base_).head<3>());
      break;
    case ObservationTermKind::kProjectedGravity:
      put3(R.transpose() * Eigen::Vector3d(0, 0, -1));
      break;
    case ObservationTermKind::kVelocityCommand:
      put3(Eigen::Vector3d(ctx.command.vx, ctx.command.vy, ctx.command.yaw_rate));
      break;
    case ObservationTermKind::kJointPos: {
      const auto q = in.qpos();
      for (size_t j = 0; j < joint_qpos_.size(); ++j) out[j] = q[joint_qpos_[j]] - default_q_[j];
      break;
    }
    case ObservationTermKind::kJointVel: {
      const auto qd = in.qvel();
      for (size_t j = 0; j < joint_dof_.size(); ++j) out[j] = qd[joint_dof_[j]];
      break;
    }
    case ObservationTermKind::kLastAction:
      for (size_t j = 0; j < out.size(); ++j)
        out[j] = j < ctx.last_action.size() ? ctx.last_action[j] : 0.0;
      break;
    case ObservationTermKind::kHeightScan: {
      if (!caster_)
        throw Error(context_.key +
                    ": height_scan needs the terrain ray caster, which this run "
                    "does not provide (control/terrain_ray_caster.h)");
      const HeightScanGrid& g = t.grid;
      const int nx = g.nx(), ny = g.ny();
      const Eigen::Vector3d p = X_WB.translation();
      const double yaw = std::atan2(R(1, 0), R(0, 0));
      const double c = std::cos(yaw), s = std::sin(yaw);
      ray_origins_.resize(static_cast<size_t>(nx) * ny);
      ray_hits_.resize(ray_origins_.size());
      for (int a = 0; a < (g.x_fastest ? ny : nx); ++a)
        for (int b = 0; b < (g.x_fastest ? nx : ny); ++b) {
          const int ix = g.x_fastest ? b : a, iy = g.x_fastest ? a : b;
          const double x = -g.size_x_m / 2 + ix * g.resolution_m;
          const double y = -g.size_y_m / 2 + iy * g.resolution_m;
          ray_origins_[static_cast<size_t>(a) * (g.x_fastest ? nx : ny) + b] =
              Eigen::Vector3d(p.x() + c * x - s * y, p.y() + s * x + c * y, p.z() + g.start_m);
        }
      caster_->CastDown(ray_origins_, g.max_distance_m, ray_hits_);
      for (size_t k = 0; k < ray_origins_.size(); ++k) {
        const double z =
            std::isnan(ray_hits_[k]) ? ray_origins_[k].z() - g.max_distance_m : ray_hits_[k];
        out[k] = p.z() - z - g.offset_m;
      }
      break;
    }
    case ObservationTermKind::kContact: {
      const auto sd = in.sensordata();
      for (size_t k = 0; k < sensor_adr_[i].size(); ++k)
        out[k] = sd[sensor_adr_[i][k]] > t.threshold_n ? 1.0 : 0.0;
      break;
    }
    case ObservationTermKind::kPhase: {
      const double a = 2 * M_PI * in.time_sec() / t.period_sec;
      out[0] = std::sin(a);
      out[1] = std::cos(a);
      break;
    }
    case ObservationTermKind::kSensor: {
      const auto sd = in.sensordata();
      for (int k = 0; k < sensor_dim_[i][0]; ++k) out[k] = sd[sensor_adr_[i][0] + k];
      break;
    }
  }
}

void PolicyObservation::Assemble(const ObservationContext& ctx, std::span<float> out) {
  if (static_cast<int>(out.size()) != size_)
    throw Error(context_.key + ": observation buffer of " + std::to_string(out.size()) +
                " values; expected " + std::to_string(size_));
  size_t pos = 0;
  for (size_t i = 0; i < terms_.size(); ++i) {
    const ObservationTermConfig& t = terms_[i];
    const int dim = term_sizes_[i];
    scratch_.assign(dim, 0.0);
    RawTerm(static_cast<int>(i), ctx, scratch_);
    for (int k = 0; k < dim; ++k) {
      double v = scratch_[k];
      const double nz = t.noise.size() == 1 ? t.noise[0] : t.noise[k];
      if (nz > 0) v += nz * SignedUniform(rng_);
      v *= t.scale.size() == 1 ? t.scale[0] : t.scale[k];
      if (t.clip) v = std::clamp(v, -*t.clip, *t.clip);
      scratch_[k] = v;
    }
    auto& h = history_[i];
    if (h.empty())
      h.assign(t.history, scratch_);
    else {
      h.pop_front();
      h.push_back(scratch_);
    }
    for (const auto& frame : h)
      for (double v : frame) out[pos++] = static_cast<float>(v);
  }
}

std::string DescribeObservationElement(const std::vector<ObservationTermConfig>& terms,
                                       const std::vector<int>& term_sizes, int64_t index) {
  int64_t pos = 0;
  for (size_t i = 0; i < terms.size() && i < term_sizes.size(); ++i) {
    const int64_t dim = std::max(term_sizes[i], 0);
    const int64_t n = dim * std::max(terms[i].history, 1);
    if (index >= pos && index < pos + n) {
      const int64_t k = index - pos;
      return "observations[" + std::to_string(i) + "] (" + ObservationTermName(terms[i].kind) +
             ") element " + std::to_string(k % dim) + ", history frame " + std::to_string(k / dim) +
             " of " + std::to_string(terms[i].history);
    }
    pos += n;
  }
  return "element " + std::to_string(index) + " (past the terms' " + std::to_string(pos) +
         " values)";
}

}  // namespace penumbra
