#pragma once
// a kinematic (MuJoCo mocap) body that compose/agent_bodies.h adds to a composed scene: its
// name, which built-in shape it has, its size and its pose at t = 0. neutral on purpose: compose
// does not know what moves the body later (the effects module's agents, posed every physics
// step through Simulation::AddMocapDriver); the caller (app/effects_stage.cc) converts its agents
// to specs.

#include <array>
#include <string>
#include <vector>

#include "penumbra/core/pose.h"

namespace penumbra {

/// one mocap body of a built-in shape (the shapes, their parts and sizes: compose/agent_bodies.h).
struct MocapBodySpec {
  /// the built-in shapes (frame B: origin on the floor, x forward, y left, z up).
  enum class Shape {
    kPerson,    ///< a standing figure of capsules and boxes, height_m tall
    kForklift,  ///< a counterbalance forklift, about 2.75 x 1.1 x 2.1 m
    kCart,      ///< a hand cart, 1.0 x 0.6 x 1.0 m
  };

  std::string name;  ///< [A-Za-z0-9_-]+, unique; the body is named "agents/<name>"
  Shape shape = Shape::kPerson;
  double height_m = 1.75;  ///< kPerson: standing height (m), (0, 3]; other shapes ignore it
  /// kPerson: sRGB colours (each channel in [0, 1]) of the shirt (torso, upper arms), the
  /// trousers (pelvis, legs) and the skin (head, neck, forearms, hands)
  std::array<double, 3> shirt_rgb{0.15, 0.35, 0.75};
  std::array<double, 3> trousers_rgb{0.12, 0.14, 0.22};
  std::array<double, 3> skin_rgb{0.80, 0.62, 0.50};
  Pose X_WB = Pose::Identity();  ///< the body frame in the world at t = 0 (m); finite

  /// @throws Error naming the spec (`index`, its name) and the field when the name is empty or
  ///         has other characters, height_m is not finite and in (0, 3], a colour channel is
  ///         outside [0, 1] or X_WB is not finite.
  void ValidateOrThrow(size_t index) const;
};

/// ValidateOrThrow for every spec, and that names are unique.
/// @throws Error naming the offending spec and field.
void ValidateMocapBodySpecsOrThrow(const std::vector<MocapBodySpec>& specs);

}  // namespace penumbra
