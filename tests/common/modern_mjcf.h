#pragma once
// a model of MuJoCo 3 features that MuJoCo 2.2.2 lacked, for the composition tests: <frame>
// with children, <replicate>, a mesh named only in a default class (the Allegro case),
// degrees and euler, and an unnamed <freejoint/> whose keyframe "stand" starts the body at
// 0.27 m, lower than its pos 0.445 m (the Go2 case).

namespace penumbra::testing {

inline constexpr const char* kModernMjcf = R"(<mujoco model="modern">
  <compiler angle="degree" autolimits="true"/>
  <default>
    <default class="shell"><geom type="mesh" mesh="tetra" rgba="0.5 0.5 0.5 1"/></default>
  </default>
  <asset>
    <mesh name="tetra" vertex="0 0 0  0.1 0 0  0 0.1 0  0 0 0.1"/>
  </asset>
  <worldbody>
    <body name="base" pos="0 0 0.445">
      <freejoint/>
      <geom name="torso" type="box" size="0.1 0.05 0.03"/>
      <frame pos="0.1 0 0" euler="0 0 90">
        <body name="arm">
          <joint name="hinge" range="-90 90"/>
          <geom name="shell" class="shell"/>
        </body>
      </frame>
      <replicate count="4" offset="0 0.02 0">
        <geom name="stud" type="sphere" size="0.01" pos="-0.1 0 -0.03"/>
      </replicate>
    </body>
  </worldbody>
  <actuator><position name="hinge" joint="hinge" kp="5"/></actuator>
  <keyframe><key name="stand" qpos="0 0 0.27 1 0 0 0 0.5" ctrl="0.5"/></keyframe>
</mujoco>
)";

}  // namespace penumbra::testing
