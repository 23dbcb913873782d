"""Robot profiles: the geometry and limits the navigator needs for each bundled mobile robot.

Figures come from the models' own descriptions (worlds/models/quadruped.xml,
worlds/models/rover.xml). Lengths in m, speeds in m/s and rad/s, angles in degrees; base
frames are REP-103 (x forward, y left, z up).
"""

from dataclasses import dataclass, field


@dataclass(frozen=True)
class RobotProfile:
    """What the navigator assumes about a robot.

    :ivar name: the profile's name (``--robot``).
    :ivar base_body: the base body's name inside the robot's model (prefixed with the
        world's robot name at run time, e.g. ``quadruped/trunk``).
    :ivar controller_type: the controller type that takes its twists.
    :ivar base_height_m: height of the base origin above the ground when standing, m (the
        ground under the robot is estimated as base z minus this).
    :ivar radius_m: radius of a disc that covers the robot's footprint about the base
        origin, m (the planner's inflation radius).
    :ivar height_m: obstacles above this height over the ground are ignored, m.
    :ivar clearance_m: points up to this height over the ground are ground, m.
    :ivar max_speed_m_s: forward speed limit, m/s.
    :ivar max_yaw_rate_rad_s: yaw-rate limit, rad/s.
    :ivar fall_height_m: the episode ends as a fall when the base origin's world z drops
        below this, m.
    :ivar max_tilt_deg: ... or when |roll| or |pitch| of the base exceeds this, deg.
    :ivar camera_mount_xyz: the camera mount's position in the base frame, m (used only
        when a camera frame carries no ``X_WO``: the camera is then taken to sit on the
        mount, looking along the base's x axis).
    """

    name: str
    base_body: str
    controller_type: str
    base_height_m: float
    radius_m: float
    height_m: float
    clearance_m: float
    max_speed_m_s: float
    max_yaw_rate_rad_s: float
    fall_height_m: float
    max_tilt_deg: float
    camera_mount_xyz: tuple = field(default=(0.0, 0.0, 0.0))


#: the Go1-class quadruped (worlds/models/quadruped.xml, trot_gait controller): trunk origin
#: 0.285 m over the ground standing; trunk 0.38 x 0.19 m, hips 0.08 m outboard, nose camera
#: at (0.215, 0, 0.07): a 0.30 m disc covers it; the camera stands 0.355 m high.
QUADRUPED = RobotProfile(
    name="quadruped", base_body="trunk", controller_type="trot_gait", base_height_m=0.285,
    radius_m=0.30, height_m=0.45, clearance_m=0.10, max_speed_m_s=0.4,
    max_yaw_rate_rad_s=1.0, fall_height_m=0.15, max_tilt_deg=45.0,
    camera_mount_xyz=(0.215, 0.0, 0.07))

#: the differential-drive rover (worlds/models/rover.xml, waypoint_follower controller):
#: chassis origin on the axle 0.05 m over the ground; deck 0.45 x 0.35 m reaching 0.27 m
#: behind the axle: a 0.33 m disc covers it; camera mount at (0.15, 0, 0.19).
ROVER = RobotProfile(
    name="rover", base_body="chassis", controller_type="waypoint_follower",
    base_height_m=0.05, radius_m=0.33, height_m=0.40, clearance_m=0.04, max_speed_m_s=0.4,
    max_yaw_rate_rad_s=1.2, fall_height_m=-0.1, max_tilt_deg=45.0,
    camera_mount_xyz=(0.15, 0.0, 0.19))

#: profiles by name.
PROFILES = {p.name: p for p in (QUADRUPED, ROVER)}
