#include "penumbra/metrics/metrics_sink.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <iterator>
#include <limits>
#include <map>
#include <nlohmann/json.hpp>

#include "penumbra/control/controller.h"
#include "penumbra/core/error.h"
#include "penumbra/core/output_file.h"
#include "penumbra/core/text_match.h"
#include "penumbra/metrics/collision_counter.h"
#include "penumbra/physics/simulation.h"

namespace penumbra {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// min / mean / max of the finite samples of one column
struct ColumnStats {
  double min = std::numeric_limits<double>::infinity();
  double max = -std::numeric_limits<double>::infinity();
  double sum = 0;
  int64_t n = 0;
  void Add(double v) {
    if (!std::isfinite(v)) return;
    min = std::min(min, v);
    max = std::max(max, v);
    sum += v;
    ++n;
  }
};

// a unit as a column-name suffix: "m/s^2" -> "m_s2", "1" -> ""
std::string UnitSuffix(const std::string& unit) {
  if (unit.empty() || unit == "1") return "";
  std::string out;
  for (char ch : unit) {
    if (ch == '/' || ch == ' ' || ch == '*' || ch == '.')
      out += '_';
    else if (ch != '^')
      out += ch;
  }
  return "_" + out;
}

// "a, b, c, ... (N in all)" for error messages
std::string SomeNames(const std::vector<std::string>& names) {
  std::string out;
  int shown = 0;
  for (const std::string& n : names) {
    if (n.empty()) continue;
    if (shown == 8) return out + ", ... (" + std::to_string(names.size()) + " in all)";
    out += (shown++ ? ", " : "") + n;
  }
  return out.empty() ? "(none)" : out;
}

// indices of the names matching any of `patterns`, in index order; each pattern must match
std::vector<int> Resolve(const std::vector<std::string>& patterns,
                         const std::vector<std::string>& names, const std::string& key,
                         const char* what) {
  std::vector<uint8_t> hit(names.size(), 0);
  for (size_t p = 0; p < patterns.size(); ++p) {
    bool any = false;
    for (size_t i = 0; i < names.size(); ++i) {
      if (names[i].empty() || !GlobMatch(patterns[p], names[i])) continue;
      hit[i] = 1;
      any = true;
    }
    if (!any)
      throw ConfigError("", 0, key + "[" + std::to_string(p) + "]",
                        "no " + std::string(what) + " matches '" + patterns[p] + "'; expected a " +
                            what + " of the composed model (\"<model>/<name>\"), e.g. " +
                            SomeNames(names));
  }
  std::vector<int> out;
  for (size_t i = 0; i < names.size(); ++i)
    if (hit[i]) out.push_back(static_cast<int>(i));
  return out;
}

int FindBody(const std::vector<std::string>& names, const std::string& name,
             const std::string& key) {
  for (size_t i = 0; i < names.size(); ++i)
    if (names[i] == name) return static_cast<int>(i);
  throw ConfigError("", 0, key,
                    "no body named '" + name + "'; expected a body of the composed model, e.g. " +
                        SomeNames(names));
}

// the model a name belongs to: "go1/trunk" -> "go1"; "" for names without a prefix
std::string ModelOf(const std::string& name) {
  const size_t slash = name.find('/');
  return slash == std::string::npos ? "" : name.substr(0, slash);
}

bool NeedsDynamics(MetricKind k) {
  return k == MetricKind::kJointTorque || k == MetricKind::kSensor ||
         k == MetricKind::kTrackingError || k == MetricKind::kContacts;
}

// the next sample index after sampling at time t (rows at the first step with t >= k / rate)
bool Due(double t, double rate_hz, int64_t* k) {
  if (rate_hz <= 0) return true;  // every step
  if (t * rate_hz + 1e-9 < static_cast<double>(*k)) return false;
  *k = static_cast<int64_t>(std::floor(t * rate_hz + 1e-9)) + 1;
  return true;
}

// the name of a contact side id (see Process): a geom (pair: geom), a body, or a geom of the
// world body (negative ids)
std::string SideName(const MetricsModel& m, bool geom_pairs, int id) {
  const int g = geom_pairs ? id : (id < 0 ? -id - 1 : -1);
  if (g < 0) return m.body_names.at(id);
  const std::string& gn = m.geom_names.at(g);
  return gn.empty() ? (geom_pairs ? "geom" + std::to_string(g) : "world") : gn;
}

}  // namespace

struct MetricsSink::Series {
  MetricConfig config;
  std::string key;
  double rate_hz = 50;
  int64_t next_row = 0, next_detect = 0;
  std::string unavailable;  // reason; "" = recorded
  SnapshotContent row_content = SnapshotContent::kState;
  std::vector<std::string> columns;
  // body_pose, body_twist
  std::vector<int> bodies;
  std::vector<int> free_dof;  // per body: dof of its free joint, or -1
  // joints, sensors, tracking: (first index, count) into the snapshot's vector
  std::vector<std::pair<int, int>> ranges;
  // distance
  int from_body = -1, to_body = -1;
  Eigen::Vector3d to_point = Eigen::Vector3d::Zero();
  double last_distance_m = kNaN;
  // contacts
  std::unique_ptr<CollisionCounter> counter;
  std::vector<std::vector<uint8_t>> between_a, between_b, exclude_a, exclude_b;  // per geom
  std::vector<std::string> geom_model;  // per geom: the model of its body ("" for the world's)
  std::string episodes_name;
  LineFile episodes;
  int64_t episode_rows = 0;
  // approach speeds at the start of each pair's current episode: (a toward b, b toward a)
  std::map<ContactPairKey, std::pair<double, double>> approach;
  std::vector<Eigen::Vector3d> prev_mover_W;  // mover origins at the previous detection
  double prev_detect_sec = kNaN;
  // output
  std::string file_name;
  LineFile file;
  int64_t rows = 0;
  std::vector<ColumnStats> stats;
};

MetricsModel MetricsModel::FromSimulation(const WorldConfig& world, const Simulation& sim) {
  MetricsModel m;
  const SceneDescription& scene = sim.scene();
  for (const Body& b : scene.bodies) {
    m.body_names.push_back(b.name);
    m.body_parent.push_back(b.parent);
  }
  int ngeom = 0;
  for (const Geom& g : scene.geoms) ngeom = std::max(ngeom, g.id + 1);
  m.geom_names.assign(ngeom, "");
  m.geom_body.assign(ngeom, 0);
  for (const Geom& g : scene.geoms) {
    if (g.id < 0) continue;
    m.geom_names[g.id] = g.name;
    m.geom_body[g.id] = g.body;
  }
  m.joints = sim.model_info().joints;
  m.sensors = sim.sensor_info();
  // Session adds the controllers of the robots that have one, in file order
  std::vector<const ModelConfig*> driven;
  for (const ModelConfig& mc : world.models)
    if (mc.is_robot && !mc.controller.type.empty()) driven.push_back(&mc);
  m.has_controllers = static_cast<int>(driven.size()) == sim.num_controllers();
  if (m.has_controllers) {
    for (int i = 0; i < sim.num_controllers(); ++i) {
      const Controller& c = sim.controller(i);
      m.controllers.push_back({driven[i]->name, c.type(), c.tracking_error_labels()});
    }
  }
  return m;
}

MetricsSink::MetricsSink(const MetricsConfig& config, MetricsModel model,
                         const std::string& out_dir, MetricsMode mode)
    : model_(std::move(model)), mode_(mode), worker_(256) {
  config.ValidateOrThrow();
  mover_ = model_.BodyMovers();
  CreateOutputFolder(out_dir, "metrics");
  const std::filesystem::path dir = std::filesystem::path(out_dir) / "metrics";
  const bool dynamics = mode == MetricsMode::kDynamics;
  for (size_t i = 0; i < config.series.size(); ++i) {
    auto s = std::make_unique<Series>();
    const MetricConfig& c = config.series[i];
    s->config = c;
    s->key = "metrics.series[" + std::to_string(i) + "]";
    s->rate_hz = config.RateOf(c);
    if (!dynamics && NeedsDynamics(c.kind))
      s->unavailable = "needs physics (" + std::string(MetricKindName(c.kind)) +
                       "); a kinematic replay only moves the bodies";
    else if (c.kind == MetricKind::kTrackingError && !model_.has_controllers)
      s->unavailable = "the simulation runs no controllers (a replay without them)";
    if (!s->unavailable.empty()) {
      spdlog::warn("metric '{}' ({}) is not recorded: {}", c.name, MetricKindName(c.kind),
                   s->unavailable);
      series_.push_back(std::move(s));
      continue;
    }
    std::vector<std::string>& cols = s->columns;
    switch (c.kind) {
      case MetricKind::kBodyPose:
      case MetricKind::kBodyTwist: {
        const bool pose = c.kind == MetricKind::kBodyPose;
        s->bodies = Resolve(c.bodies, model_.body_names, s->key + ".bodies", "body");
        s->row_content = pose || !dynamics ? SnapshotContent::kPoses : SnapshotContent::kFull;
        for (int b : s->bodies) {
          const std::string& n = model_.body_names[b];
          if (pose) {
            for (const char* suffix : {"_x_m", "_y_m", "_z_m", "_qw", "_qx", "_qy", "_qz"})
              cols.push_back(n + suffix);
            continue;
          }
          for (const char* suffix :
               {"_wx_rad_s", "_wy_rad_s", "_wz_rad_s", "_vx_m_s", "_vy_m_s", "_vz_m_s"})
            cols.push_back(n + suffix);
          int dof = -1;
          for (const JointInfo& j : model_.joints)
            if (j.body == b && j.type == JointInfo::Type::kFree) dof = j.dof_adr;
          if (!dynamics && dof < 0)
            throw ConfigError("", 0, s->key + ".bodies",
                              "body '" + n +
                                  "' has no free joint: its twist needs physics (V_WB) in a "
                                  "kinematic replay; expected bodies moved by a free joint");
          s->free_dof.push_back(dof);
        }
        break;
      }
      case MetricKind::kJointPosition:
      case MetricKind::kJointVelocity:
      case MetricKind::kJointTorque: {
        std::vector<std::string> names;
        for (const JointInfo& j : model_.joints) names.push_back(j.name);
        const std::vector<int> joints = Resolve(c.joints, names, s->key + ".joints", "joint");
        s->row_content =
            c.kind == MetricKind::kJointTorque ? SnapshotContent::kFull : SnapshotContent::kState;
        for (int ji : joints) {
          const JointInfo& j = model_.joints[ji];
          std::vector<const char*> sfx;
          using T = JointInfo::Type;
          if (c.kind == MetricKind::kJointPosition) {
            if (j.type == T::kHinge) sfx = {"_rad"};
            if (j.type == T::kSlide) sfx = {"_m"};
            if (j.type == T::kBall) sfx = {"_qw", "_qx", "_qy", "_qz"};
            if (j.type == T::kFree) sfx = {"_x_m", "_y_m", "_z_m", "_qw", "_qx", "_qy", "_qz"};
          } else if (c.kind == MetricKind::kJointVelocity) {
            if (j.type == T::kHinge) sfx = {"_rad_s"};
            if (j.type == T::kSlide) sfx = {"_m_s"};
            if (j.type == T::kBall) sfx = {"_wx_rad_s", "_wy_rad_s", "_wz_rad_s"};
            if (j.type == T::kFree)
              sfx = {"_vx_m_s", "_vy_m_s", "_vz_m_s", "_wx_rad_s", "_wy_rad_s", "_wz_rad_s"};
          } else {
            if (j.type == T::kHinge) sfx = {"_N_m"};
            if (j.type == T::kSlide) sfx = {"_N"};
            if (j.type == T::kBall) sfx = {"_tx_N_m", "_ty_N_m", "_tz_N_m"};
            if (j.type == T::kFree)
              sfx = {"_fx_N", "_fy_N", "_fz_N", "_tx_N_m", "_ty_N_m", "_tz_N_m"};
          }
          const int first = c.kind == MetricKind::kJointPosition ? j.qpos_adr : j.dof_adr;
          s->ranges.push_back({first, static_cast<int>(sfx.size())});
          for (const char* x : sfx) cols.push_back(j.name + x);
        }
        break;
      }
      case MetricKind::kDistance:
        s->from_body = FindBody(model_.body_names, c.body, s->key + ".body");
        if (!c.to_body.empty())
          s->to_body = FindBody(model_.body_names, c.to_body, s->key + ".to_body");
        else
          s->to_point = *c.to_point_m;
        s->row_content = SnapshotContent::kPoses;
        cols.push_back("distance_m");
        break;
      case MetricKind::kSensor: {
        std::vector<std::string> names;
        for (const SensorDescription& d : model_.sensors) names.push_back(d.name);
        for (int si : Resolve(c.sensors, names, s->key + ".sensors", "MJCF sensor")) {
          const SensorDescription& d = model_.sensors[si];
          s->ranges.push_back({d.adr, d.dim});
          for (int k = 0; k < d.dim; ++k)
            cols.push_back(SensorValueLabel(d, k) + UnitSuffix(d.unit));
        }
        s->row_content = SnapshotContent::kFull;
        break;
      }
      case MetricKind::kTrackingError: {
        int offset = 0;
        bool found = false;
        for (const MetricsModel::ControllerTracking& t : model_.controllers) {
          if (t.robot == c.robot) {
            if (t.labels.empty())
              throw ConfigError("", 0, s->key + ".robot",
                                "the controller of robot '" + c.robot + "' (" + t.type +
                                    ") reports no tracking error; expected a robot driven by "
                                    "waypoint_follower, trot_gait or policy");
            s->ranges.push_back({offset, static_cast<int>(t.labels.size())});
            for (const std::string& l : t.labels) cols.push_back(c.robot + "/" + l);
            found = true;
          }
          offset += static_cast<int>(t.labels.size());
        }
        if (!found) {
          std::vector<std::string> robots;
          for (const auto& t : model_.controllers) robots.push_back(t.robot);
          throw ConfigError("", 0, s->key + ".robot",
                            "no robot '" + c.robot +
                                "' with a controller; expected one of: " + SomeNames(robots));
        }
        s->row_content = SnapshotContent::kFull;
        break;
      }
      case MetricKind::kContacts: {
        s->counter = std::make_unique<CollisionCounter>(c.min_force_N, c.debounce_sec);
        const size_t ng = model_.geom_names.size();
        auto side_matches = [&](const std::string& pattern) {
          std::vector<uint8_t> m(ng, 0);
          for (size_t g = 0; g < ng; ++g) {
            const int b = model_.geom_body[g];
            m[g] = GlobMatch(pattern, model_.geom_names[g]) ||
                   (b >= 0 && b < static_cast<int>(model_.body_names.size()) &&
                    GlobMatch(pattern, model_.body_names[b]));
          }
          return m;
        };
        for (const ContactPairRule& r : c.between) {
          s->between_a.push_back(side_matches(r.a));
          s->between_b.push_back(side_matches(r.b));
        }
        for (const ContactPairRule& r : c.exclude) {
          s->exclude_a.push_back(side_matches(r.a));
          s->exclude_b.push_back(side_matches(r.b));
        }
        s->geom_model.resize(ng);
        for (size_t g = 0; g < ng; ++g) {
          const int b = model_.geom_body[g];
          // geoms of the world body (floors, walls) belong to no model: never a self contact
          s->geom_model[g] = b > 0 ? ModelOf(model_.body_names[b]) : "";
        }
        s->row_content = SnapshotContent::kFull;
        cols = {"contacts", "pairs_in_collision", "normal_force_N", "max_pair_force_N",
                "collisions"};
        s->episodes_name = c.name + "_episodes.csv";
        s->episodes = LineFile(dir / s->episodes_name);
        s->episodes.Append(
            "episode,a,b,start_sec,end_sec,peak_force_N,a_speed_toward_b_m_s,"
            "b_speed_toward_a_m_s\n");
        break;
      }
    }
    s->file_name = c.name + ".csv";
    s->file = LineFile(dir / s->file_name);
    std::string header = "step,time_sec";
    for (const std::string& col : cols) header += "," + col;
    s->file.Append(header + "\n");
    s->stats.resize(cols.size());
    series_.push_back(std::move(s));
  }
}

MetricsSink::~MetricsSink() { worker_.Finish(); }

std::vector<int> MetricsModel::BodyMovers() const {
  const int n = static_cast<int>(body_names.size());
  std::vector<int> top(n, 0);
  std::map<std::string, int> world_children;
  for (int b = 1; b < n; ++b) {
    int r = b;
    for (int guard = 0;
         guard < n && r > 0 && r < static_cast<int>(body_parent.size()) && body_parent[r] > 0;
         ++guard)
      r = body_parent[r];
    top[b] = r;
    if (r == b) world_children[body_names[b]] = b;
  }
  // a world child named "<other world child>/<part>" moves with that one (an agent's parts)
  std::vector<int> mover(n, 0);
  for (int b = 1; b < n; ++b) {
    const std::string& name = body_names[top[b]];
    const size_t slash = name.rfind('/');
    const auto it = slash == std::string::npos ? world_children.end()
                                               : world_children.find(name.substr(0, slash));
    mover[b] = it != world_children.end() ? it->second : top[b];
  }
  return mover;
}

void MetricsSink::OnStart(const LoopStart& start) { worker_.Start(start.report_error); }

SnapshotContent MetricsSink::Wants(int64_t step, double t) {
  due_rows_.assign(series_.size(), 0);
  due_detect_.assign(series_.size(), 0);
  due_step_ = step;
  SnapshotContent want = SnapshotContent::kNone;
  for (size_t i = 0; i < series_.size(); ++i) {
    Series& s = *series_[i];
    if (!s.unavailable.empty()) continue;
    if (s.counter && Due(t, s.config.detect_hz, &s.next_detect)) {
      due_detect_[i] = 1;
      want = Richer(want, SnapshotContent::kFull);
    }
    if (Due(t, s.rate_hz, &s.next_row)) {
      due_rows_[i] = 1;
      want = Richer(want, s.row_content);
    }
  }
  return want;
}

void MetricsSink::OnSnapshot(const std::shared_ptr<const WorldSnapshot>& snapshot) {
  if (snapshot->step != due_step_) return;
  due_step_ = -1;
  worker_.Post([this, snapshot, rows = due_rows_, detect = due_detect_] {
    Process(*snapshot, rows, detect);
  });
}

void MetricsSink::Process(const WorldSnapshot& snap, const std::vector<uint8_t>& rows,
                          const std::vector<uint8_t>& detect) {
  std::vector<double> v;
  for (size_t i = 0; i < series_.size(); ++i) {
    if (!rows[i] && !detect[i]) continue;
    Series& s = *series_[i];
    v.clear();
    switch (s.config.kind) {
      case MetricKind::kBodyPose:
        for (int b : s.bodies) {
          const Pose& X = snap.X_WB.at(b);
          const Eigen::Quaterniond q(X.linear());
          const Eigen::Vector3d p = X.translation();
          v.insert(v.end(), {p.x(), p.y(), p.z(), q.w(), q.x(), q.y(), q.z()});
        }
        break;
      case MetricKind::kBodyTwist:
        for (size_t k = 0; k < s.bodies.size(); ++k) {
          const int b = s.bodies[k];
          if (!snap.V_WB.empty()) {
            for (int e = 0; e < 6; ++e) v.push_back(snap.V_WB.at(b)[e]);
            continue;
          }
          // free joint: qvel = (linear, world axes; angular, body axes)
          const int d = s.free_dof[k];
          const Eigen::Vector3d w_B(snap.qvel.at(d + 3), snap.qvel.at(d + 4), snap.qvel.at(d + 5));
          const Eigen::Vector3d w_W = snap.X_WB.at(b).linear() * w_B;
          v.insert(v.end(), {w_W.x(), w_W.y(), w_W.z(), snap.qvel.at(d), snap.qvel.at(d + 1),
                             snap.qvel.at(d + 2)});
        }
        break;
      case MetricKind::kJointPosition:
      case MetricKind::kJointVelocity:
      case MetricKind::kJointTorque:
      case MetricKind::kSensor:
      case MetricKind::kTrackingError: {
        const std::vector<double>& src =
            s.config.kind == MetricKind::kJointPosition   ? snap.qpos
            : s.config.kind == MetricKind::kJointVelocity ? snap.qvel
            : s.config.kind == MetricKind::kJointTorque   ? snap.qfrc_actuator
            : s.config.kind == MetricKind::kSensor        ? snap.sensordata
                                                          : snap.tracking_error;
        for (const auto& [first, n] : s.ranges)
          for (int e = 0; e < n; ++e) {
            const size_t at = static_cast<size_t>(first + e);
            if (at >= src.size())
              throw Error("metric '" + s.config.name + "' (" +
                          std::string(MetricKindName(s.config.kind)) + "): the snapshot of step " +
                          std::to_string(snap.step) + " lacks its values (" +
                          std::to_string(src.size()) + " given)");
            v.push_back(src[at]);
          }
        break;
      }
      case MetricKind::kDistance: {
        const Eigen::Vector3d goal =
            s.to_body >= 0 ? Eigen::Vector3d(snap.X_WB.at(s.to_body).translation()) : s.to_point;
        s.last_distance_m = (snap.X_WB.at(s.from_body).translation() - goal).norm();
        v.push_back(s.last_distance_m);
        break;
      }
      case MetricKind::kContacts: {
        const MetricConfig& c = s.config;
        std::map<ContactPairKey, double> pair_force;
        struct Strongest {
          double force_N = -1;
          Eigen::Vector3d p_W = Eigen::Vector3d::Zero(), n_ab = Eigen::Vector3d::UnitX();
        };
        std::map<ContactPairKey, Strongest> strongest;
        int n = 0;
        double total = 0;
        const int ng = static_cast<int>(s.geom_model.size());
        for (const WorldSnapshot::Contact& ct : snap.contacts) {
          const int g1 = ct.geom1, g2 = ct.geom2;
          if (g1 < 0 || g2 < 0 || g1 >= ng || g2 >= ng) continue;
          if (!c.self_contacts && !s.geom_model[g1].empty() && s.geom_model[g1] == s.geom_model[g2])
            continue;
          auto pair_in = [&](const std::vector<std::vector<uint8_t>>& a,
                             const std::vector<std::vector<uint8_t>>& b) {
            for (size_t r = 0; r < a.size(); ++r)
              if ((a[r][g1] && b[r][g2]) || (a[r][g2] && b[r][g1])) return true;
            return false;
          };
          if (!c.between.empty() && !pair_in(s.between_a, s.between_b)) continue;
          if (pair_in(s.exclude_a, s.exclude_b)) continue;
          // a side: the geom (pair: geom) or its body; geoms of the world body stand alone
          auto side = [&](int g) {
            if (c.geom_pairs) return g;
            const int b = model_.geom_body[g];
            return b > 0 ? b : -(g + 1);
          };
          // pairs list moving sides first (robots are composed first), world geoms last
          auto fixed = [&](int id) { return c.geom_pairs ? model_.geom_body[id] == 0 : id < 0; };
          int a = side(g1), b = side(g2);
          if (fixed(a) != fixed(b) ? fixed(a) : a > b) std::swap(a, b);
          const double fn = std::max(0.0, ct.force_N.x());
          // the pair's strongest contact: its point and its normal from side a towards b
          Strongest& st = strongest[{a, b}];
          if (fn >= st.force_N) {
            st.force_N = fn;
            st.p_W = ct.p_W;
            st.n_ab = side(g1) == a ? ct.normal_W : Eigen::Vector3d(-ct.normal_W);
          }
          pair_force[{a, b}] += fn;
          total += fn;
          ++n;
        }
        if (detect[i]) {
          const std::map<ContactPairKey, int64_t> before = s.counter->count_by_pair();
          s.counter->Update(snap.time_sec, pair_force);
          // mover origins now and their velocities since the previous detection
          std::vector<Eigen::Vector3d> mover_W(mover_.size(), Eigen::Vector3d::Zero());
          for (size_t b = 0; b < mover_.size() && b < snap.X_WB.size(); ++b)
            mover_W[b] = snap.X_WB[b].translation();
          const double dt = snap.time_sec - s.prev_detect_sec;
          const bool have_prev =
              std::isfinite(dt) && dt > 0 && s.prev_mover_W.size() == mover_W.size();
          for (const auto& [pair, count] : s.counter->count_by_pair()) {
            const auto it = before.find(pair);
            if (it != before.end() && it->second == count) continue;  // no new episode
            s.approach[pair] =
                ApproachSpeeds(pair, strongest[pair].p_W, strongest[pair].n_ab, c.geom_pairs,
                               mover_W, have_prev ? &s.prev_mover_W : nullptr, dt);
          }
          s.prev_mover_W = std::move(mover_W);
          s.prev_detect_sec = snap.time_sec;
          for (const CollisionEpisode& e : s.counter->TakeClosed()) AppendEpisode(&s, e);
        }
        int active = 0;
        double max_pair = 0;
        for (const auto& [pair, f] : pair_force) {
          active += f >= c.min_force_N;
          max_pair = std::max(max_pair, f);
        }
        v = {static_cast<double>(n), static_cast<double>(active), total, max_pair,
             static_cast<double>(s.counter->count())};
        if (!rows[i]) continue;
        break;
      }
    }
    if (!rows[i]) continue;
    std::string row = fmt::format("{},{:.9g}", snap.step, snap.time_sec);
    for (size_t k = 0; k < v.size(); ++k) {
      fmt::format_to(std::back_inserter(row), ",{:.9g}", v[k]);
      s.stats[k].Add(v[k]);
    }
    row += '\n';
    s.file.Append(row);
    ++s.rows;
  }
}

void MetricsSink::AppendEpisode(Series* s, const CollisionEpisode& e) {
  const auto it = s->approach.find(e.pair);
  const std::pair<double, double> v = it == s->approach.end() ? std::pair{0.0, 0.0} : it->second;
  s->episodes.Append(fmt::format("{},{},{},{:.9g},{:.9g},{:.9g},{:.6g},{:.6g}\n", ++s->episode_rows,
                                 SideName(model_, s->config.geom_pairs, e.pair.first),
                                 SideName(model_, s->config.geom_pairs, e.pair.second), e.start_sec,
                                 e.end_sec, e.peak_force_N, v.first + 0.0,
                                 v.second + 0.0));  // + 0.0: no "-0"
}

std::pair<double, double> MetricsSink::ApproachSpeeds(
    const ContactPairKey& pair, const Eigen::Vector3d& p_contact_W, const Eigen::Vector3d& n_ab,
    bool geom_pairs, const std::vector<Eigen::Vector3d>& mover_W,
    const std::vector<Eigen::Vector3d>* prev_mover_W, double dt) const {
  // the mover of a side (its body's, see MetricsModel::body_mover), or -1 for a world geom
  const auto mover = [&](int id) {
    const int body = geom_pairs ? model_.geom_body.at(id) : id;
    return body > 0 && body < static_cast<int>(mover_.size()) ? mover_[body] : -1;
  };
  const int ma = mover(pair.first), mb = mover(pair.second);
  const auto position = [&](int m) { return m > 0 ? mover_W[m] : p_contact_W; };
  const auto velocity = [&](int m) -> Eigen::Vector3d {
    if (m <= 0 || !prev_mover_W) return Eigen::Vector3d::Zero();
    return (mover_W[m] - (*prev_mover_W)[m]) / dt;
  };
  // the horizontal line from a's mover to b's (a world geom: the contact point)
  Eigen::Vector3d u = position(mb) - position(ma);
  u.z() = 0;
  if (u.norm() < 1e-6) {
    u = n_ab;
    u.z() = 0;
  }
  if (u.norm() < 1e-9) return {0.0, 0.0};
  u.normalize();
  return {velocity(ma).dot(u), -velocity(mb).dot(u)};
}

void MetricsSink::OnFinish(const LoopFinish&) {
  worker_.Finish();
  for (auto& sp : series_) {
    Series& s = *sp;
    if (s.counter) {
      s.counter->Finish();
      for (const CollisionEpisode& e : s.counter->TakeClosed()) AppendEpisode(&s, e);
      s.episodes.Close();
    }
    s.file.Close();
  }
}

std::string MetricsSink::SummaryJson() const {
  nlohmann::ordered_json all = nlohmann::ordered_json::object();
  for (const auto& sp : series_) {
    const Series& s = *sp;
    nlohmann::ordered_json j;
    j["type"] = std::string(MetricKindName(s.config.kind));
    if (!s.unavailable.empty()) {
      j["unavailable"] = s.unavailable;
      all[s.config.name] = j;
      continue;
    }
    j["file"] = "metrics/" + s.file_name;
    j["rate_hz"] = s.rate_hz;
    j["rows"] = s.rows;
    nlohmann::ordered_json cols = nlohmann::ordered_json::object();
    for (size_t k = 0; k < s.columns.size(); ++k) {
      const ColumnStats& st = s.stats[k];
      nlohmann::ordered_json c;
      if (st.n == 0) {
        c["min"] = nullptr;
        c["mean"] = nullptr;
        c["max"] = nullptr;
      } else {
        c["min"] = st.min;
        c["mean"] = st.sum / static_cast<double>(st.n);
        c["max"] = st.max;
      }
      cols[s.columns[k]] = c;
    }
    j["columns"] = cols;
    if (s.config.kind == MetricKind::kDistance) {
      if (std::isfinite(s.last_distance_m))
        j["final_distance_m"] = s.last_distance_m;
      else
        j["final_distance_m"] = nullptr;
    }
    if (s.counter) {
      j["collisions"] = s.counter->count();
      nlohmann::ordered_json by = nlohmann::ordered_json::object();
      for (const auto& [pair, n] : s.counter->count_by_pair()) {
        auto name = [&](int id) { return SideName(model_, s.config.geom_pairs, id); };
        by[name(pair.first) + " | " + name(pair.second)] = n;
      }
      j["collisions_by_pair"] = by;
      j["peak_force_N"] = s.counter->peak_force_N();
      j["episodes_file"] = "metrics/" + s.episodes_name;
    }
    all[s.config.name] = j;
  }
  return all.dump();
}

std::vector<std::string> MetricsSink::Columns(const std::string& name) const {
  for (const auto& s : series_)
    if (s->config.name == name) return s->columns;
  return {};
}

std::unique_ptr<MetricsSink> MakeMetricsSink(const WorldConfig& world, const Simulation& sim,
                                             const std::string& out_dir, MetricsMode mode) {
  if (!world.metrics.enabled()) return nullptr;
  return std::make_unique<MetricsSink>(world.metrics, MetricsModel::FromSimulation(world, sim),
                                       out_dir, mode);
}

}  // namespace penumbra
