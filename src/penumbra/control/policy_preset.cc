#include "penumbra/control/policy_preset.h"

namespace penumbra {
namespace {

struct ConventionName {
  PolicyConvention convention;
  const char* name;
};

constexpr ConventionName kConventionNames[] = {
    {PolicyConvention::kLeggedGym, "legged_gym"},
    {PolicyConvention::kLeggedGymRough, "legged_gym_rough"},
    {PolicyConvention::kIsaacLab, "isaac_lab"},
    {PolicyConvention::kIsaacLabRough, "isaac_lab_rough"},
    {PolicyConvention::kMjlab, "mjlab"},
};

ObservationTermConfig Term(ObservationTermKind kind, std::vector<double> scale = {1.0},
                           std::optional<double> clip = std::nullopt) {
  ObservationTermConfig t;
  t.kind = kind;
  t.scale = std::move(scale);
  t.clip = clip;
  return t;
}

// the 1.6 x 1.0 m height scan at 0.1 m, 0.5 m offset, that legged_gym's and Isaac Lab's rough
// terrain configurations both use; scale = clip, in their own grid order
ObservationTermConfig HeightScanTerm(double scale_and_clip, bool x_fastest) {
  ObservationTermConfig h =
      Term(ObservationTermKind::kHeightScan, {scale_and_clip}, scale_and_clip);
  h.grid.size_x_m = 1.6;
  h.grid.size_y_m = 1.0;
  h.grid.resolution_m = 0.1;
  h.grid.offset_m = 0.5;
  h.grid.x_fastest = x_fastest;
  return h;
}

}  // namespace

const char* PolicyConventionName(PolicyConvention convention) {
  for (const ConventionName& c : kConventionNames)
    if (c.convention == convention) return c.name;
  return "?";
}

std::optional<PolicyConvention> PolicyConventionFromName(const std::string& name) {
  for (const ConventionName& c : kConventionNames)
    if (name == c.name) return c.convention;
  return std::nullopt;
}

std::string PolicyConventionNames() {
  std::string s;
  for (const ConventionName& c : kConventionNames)
    s += (s.empty() ? "" : ", ") + std::string(c.name);
  return s;
}

PolicyPreset MakePolicyPreset(PolicyConvention convention) {
  using K = ObservationTermKind;
  PolicyPreset p;
  p.rate_hz = 50;
  p.action.kind = PolicyActionKind::kJointPosition;
  p.action.scale = {0.5};
  switch (convention) {
    case PolicyConvention::kLeggedGym:
    case PolicyConvention::kLeggedGymRough: {
      // obs_scales lin_vel 2, ang_vel 0.25, dof_pos 1, dof_vel 0.05; commands_scale
      // (lin_vel, lin_vel, ang_vel); clip_observations 100; clip_actions 100
      constexpr double kClip = 100;
      p.observations = {Term(K::kBaseLinVel, {2.0}, kClip),
                        Term(K::kBaseAngVel, {0.25}, kClip),
                        Term(K::kProjectedGravity, {1.0}, kClip),
                        Term(K::kVelocityCommand, {2.0, 2.0, 0.25}, kClip),
                        Term(K::kJointPos, {1.0}, kClip),
                        Term(K::kJointVel, {0.05}, kClip),
                        Term(K::kLastAction, {1.0}, kClip)};
      if (convention == PolicyConvention::kLeggedGymRough) {
        p.observations.push_back(HeightScanTerm(5.0, /*x_fastest=*/false));
      }
      p.action.clip = 100;
      break;
    }
    case PolicyConvention::kIsaacLab:
    case PolicyConvention::kIsaacLabRough:
      p.observations = {Term(K::kBaseLinVel),      Term(K::kBaseAngVel), Term(K::kProjectedGravity),
                        Term(K::kVelocityCommand), Term(K::kJointPos),   Term(K::kJointVel),
                        Term(K::kLastAction)};
      if (convention == PolicyConvention::kIsaacLabRough) {
        p.observations.push_back(HeightScanTerm(1.0, /*x_fastest=*/true));
      }
      break;
    case PolicyConvention::kMjlab:
      p.observations = {Term(K::kBaseLinVel),     Term(K::kBaseAngVel), Term(K::kProjectedGravity),
                        Term(K::kJointPos),       Term(K::kJointVel),   Term(K::kLastAction),
                        Term(K::kVelocityCommand)};
      break;
  }
  return p;
}

}  // namespace penumbra
