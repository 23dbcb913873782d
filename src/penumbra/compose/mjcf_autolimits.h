#pragma once
// MuJoCo 3's `autolimits` for MJCF read by MuJoCo 2.2.2. since MuJoCo 2.2.2 the compiler
// attribute `autolimits` exists but defaults to "false", and a joint, tendon or actuator that
// has a range (range, ctrlrange, forcerange, actrange) without the matching limited attribute
// (limited, ctrllimited, forcelimited, actlimited) is an error ("joint has `range` but not
// `limited`"); MuJoCo 3 defaults it to "true", which limits every such element. models written
// for MuJoCo 3 (MuJoCo Menagerie's Z1, Spot, ...) rely on that and leave `limited` out.
// internal to src/penumbra/compose.

#include <string>
#include <vector>

#include "penumbra/compose/mjcf_source.h"

namespace penumbra::compose {

/// what ApplyMujoco3Autolimits changed: per kind of element, the names (or "<tag> at line N"
/// for unnamed ones) that got limited="true" (or ctrllimited, forcelimited, actlimited).
struct AutolimitsChange {
  std::vector<std::string> joints, tendons;
  std::vector<std::string> actuator_ctrl, actuator_force, actuator_act;
  /// number of attributes set in all.
  size_t total() const {
    return joints.size() + tendons.size() + actuator_ctrl.size() + actuator_force.size() +
           actuator_act.size();
  }
};

/// for an MJCF model whose <compiler> does not set autolimits (MuJoCo 3 then defaults it to
/// "true"): writes limited="true" on every joint and tendon (spatial, fixed) that has a range
/// and no limited, and ctrllimited / forcelimited / actlimited="true" on every actuator that
/// has a ctrlrange / forcerange / actrange without them (ctrllimited not on <adhesion> and
/// <damper>, actlimited only on <general>: MuJoCo 2.2.2 has those attributes only there),
/// each range or limited written on the
/// element or inherited from its default class (class=, else the enclosing body's
/// childclass, then the class's parents; actuator defaults of any actuator tag share one slot
/// per class, the last written winning, as MuJoCo's parser does). a limited="auto" counts as
/// unset. when anything changed, appends ONE warning naming the model file, the counts per
/// kind and the names (up to 8 per kind). models that set autolimits (either value) and URDF
/// models are left as they are.
/// @throws ConfigError for an unknown default class (as DefaultTree::ClassOf).
AutolimitsChange ApplyMujoco3Autolimits(const MjcfSource& src, std::vector<std::string>* warnings);

}  // namespace penumbra::compose
