"""The point-goal navigation loop over a lockstep Penumbra run (docs/navigation.md).

Each control period the navigator steps the run by N physics steps, reads the newest depth
frame (with the pose of its optical frame, ``X_WO``) and the base body's ground-truth pose
X_WB, folds the frame into a world-frame occupancy grid, replans with A* when due or when
the path ahead is blocked, and sends the pure-pursuit twist. The episode ends when the base
origin is within the goal radius (success), at the timeout (sim seconds), on a fall, or when
the run ends. Frames: world W is REP-103 (x forward, y left, z up); camera images are in the
OpenCV optical frame (x right, y down, z forward).
"""

import json
import math
import sys
import time
from dataclasses import asdict, dataclass
from typing import Optional

import numpy as np

from penumbra_client import RunEndedError

from .contacts import ContactLog
from .geometry import R_BODY_OPTICAL, pose_from_msg, pose_matrix, roll_pitch_of, yaw_of
from .occupancy_grid import OccupancyGrid
from .planner import Planner, path_length
from .pure_pursuit import PurePursuit
from .robots import PROFILES

GROUND_TRUTH_TOPIC = "ground_truth/poses"
CONTACTS_TOPIC = "contacts"


@dataclass
class NavigatorConfig:
    """The navigator's parameters (units in the names; defaults in docs/navigation.md).

    None means: take it from the robot profile (:mod:`penumbra_nav.robots`) or the camera.
    """

    goal_xy: tuple
    goal_radius_m: float = 0.5
    timeout_sec: float = 60.0
    robot: str = "quadruped"
    robot_name: Optional[str] = None
    camera: Optional[str] = None
    control_period_sec: Optional[float] = None
    replan_every: int = 5
    resolution_m: float = 0.05
    grid_size_m: Optional[float] = None
    max_range_m: float = 4.0
    pixel_stride: Optional[int] = None
    robot_radius_m: Optional[float] = None
    unknown_cost: float = 0.5
    clearance_m: float = 0.2
    clearance_cost: float = 1.0
    lookahead_m: float = 0.6
    max_speed_m_s: Optional[float] = None
    max_yaw_rate_rad_s: Optional[float] = None
    turn_in_place_deg: float = 60.0
    search_yaw_rate_rad_s: float = 0.5
    floor_z: Optional[float] = None
    log_contacts: bool = True
    reset: bool = False


def pick_camera(info, name=None):
    """The camera map of ``name``, or of the first camera that outputs depth.

    :raises ValueError: no such camera, or it has no depth output.
    """
    cameras = info.raw.get("cameras", [])
    if name is None:
        for cam in cameras:
            if "depth" in cam.get("outputs", []):
                return cam
        raise ValueError(f"no camera outputs depth; cameras: "
                         f"{[(c['name'], c.get('outputs')) for c in cameras]}")
    try:
        cam = info.camera(name)
    except KeyError as e:
        raise ValueError(str(e)) from None
    if "depth" not in cam.get("outputs", []):
        raise ValueError(f"camera '{name}' outputs {cam.get('outputs')}, not depth")
    return cam


def pick_robot(info, profile, name=None):
    """The world's name of the robot to drive: ``name``, else the only controller that takes
    twists, else the only one of the profile's controller type.

    :raises ValueError: no (or no unique) such controller.
    """
    twistable = [c for c in info.raw.get("controllers", []) if "twist" in c.get("commands", [])]
    if name is not None:
        if not any(c["robot"] == name for c in twistable):
            raise ValueError(f"robot '{name}' has no controller that takes twists; those that "
                             f"do: {[c['robot'] for c in twistable]}")
        return name
    if len(twistable) == 1:
        return twistable[0]["robot"]
    typed = [c for c in twistable if c.get("type") == profile.controller_type]
    if len(typed) == 1:
        return typed[0]["robot"]
    raise ValueError(f"cannot tell which robot to drive among {[c['robot'] for c in twistable]}"
                     " (pass --robot-name)")


def base_pose_from_ground_truth(header, base_body):
    """(xyz, qwxyz) of ``base_body`` in a ``ground_truth/poses`` header (X_WB), or None."""
    try:
        k = header["name"].index(base_body)
    except ValueError:
        return None
    return np.asarray(header["xyz"][k], dtype=np.float64), \
        np.asarray(header["qwxyz"][k], dtype=np.float64)


def base_pose_from_state(state, info, base_body):
    """(xyz, qwxyz) of ``base_body`` from its free joint in ``get_state``'s qpos, or None."""
    body_id = info.body(base_body)["id"]
    for j in info.raw.get("joints", []):
        if j["body"] == body_id and j["type"] == "free":
            a = j["qpos_adr"]
            return state.qpos[a:a + 3].copy(), state.qpos[a + 3:a + 7].copy()
    return None


def camera_pose(header, base_xyz, base_qwxyz, profile):
    """X_WC (4 x 4) of a camera frame: its header's ``X_WO`` when present, else the robot
    profile's camera mount on the base pose with the optical frame looking along the base's
    x axis (a fallback for servers that do not publish ``X_WO``)."""
    if "X_WO" in header:
        return pose_from_msg(header["X_WO"])
    X_WB = pose_matrix(base_xyz, base_qwxyz)
    X_BC = np.eye(4)
    X_BC[:3, :3] = R_BODY_OPTICAL
    X_BC[:3, 3] = profile.camera_mount_xyz
    return X_WB @ X_BC


class Navigator:
    """Drives one robot to a point goal over a connected
    :class:`penumbra_client.Client` (lockstep run).

    :param client: a connected client (``hello`` done).
    :param config: a :class:`NavigatorConfig`.
    :param log: a text stream for progress lines (None: silent).
    :param trace: a text stream for one JSON line per control period (None: none).
    """

    def __init__(self, client, config, log=None, trace=None):
        self.client = client
        self.config = config
        self.log = log
        self.trace = trace
        if config.robot not in PROFILES:
            raise ValueError(f"robot: '{config.robot}'; expected one of {sorted(PROFILES)}")
        self.profile = PROFILES[config.robot]
        self.grid = None
        self.path = None

    def _say(self, text):
        if self.log is not None:
            print(f"penumbra_nav: {text}", file=self.log, flush=True)

    def _make_grid(self, start_xy, goal_xy):
        cfg = self.config
        d = float(np.hypot(*(np.asarray(goal_xy) - start_xy)))
        size = cfg.grid_size_m or max(12.0, 2.0 * d + 6.0)
        center = 0.5 * (np.asarray(start_xy) + np.asarray(goal_xy))
        return OccupancyGrid(resolution_m=cfg.resolution_m, size_m=size, center_xy=center)

    def run(self):
        """Runs one episode; returns the episode dict (see docs/navigation.md)."""
        cfg = self.config
        prof = self.profile
        c = self.client
        wall0 = time.monotonic()
        info = c.model_info()
        robot = pick_robot(info, prof, cfg.robot_name)
        base_body = f"{robot}/{prof.base_body}"
        try:
            info.body(base_body)
        except KeyError as e:
            raise ValueError(f"robot '{robot}' with profile '{prof.name}': {e}") from None
        cam = pick_camera(info, cfg.camera)
        depth_topic = f"camera/{cam['name']}/depth"
        dt = info.timestep_sec
        period = cfg.control_period_sec or 1.0 / cam["rate_hz"]
        n_steps = max(1, int(round(period / dt)))
        stride = cfg.pixel_stride or max(1, int(math.ceil(cam["width"] / 160)))
        radius = cfg.robot_radius_m if cfg.robot_radius_m is not None else prof.radius_m
        max_speed = cfg.max_speed_m_s if cfg.max_speed_m_s is not None else prof.max_speed_m_s
        max_yaw = (cfg.max_yaw_rate_rad_s if cfg.max_yaw_rate_rad_s is not None
                   else prof.max_yaw_rate_rad_s)
        goal = np.asarray(cfg.goal_xy, dtype=np.float64)

        topics = [depth_topic, GROUND_TRUTH_TOPIC] + ([CONTACTS_TOPIC] if cfg.log_contacts
                                                      else [])
        c.subscribe(topics)
        contact_log = ContactLog({b["id"]: b["name"] for b in info.raw.get("bodies", [])},
                                 robot + "/")
        if cfg.reset:
            c.reset()
        state = c.get_state()
        t0 = float(state.time_sec)
        step0 = state.step
        pose = base_pose_from_state(state, info, base_body)
        if pose is None:
            raise ValueError(f"body '{base_body}' has no free joint")
        xyz, q = pose
        start_xy = xyz[:2].copy()
        self.grid = grid = self._make_grid(start_xy, goal)
        planner = Planner(robot_radius_m=radius, unknown_cost=cfg.unknown_cost,
                          clearance_m=cfg.clearance_m, clearance_cost=cfg.clearance_cost)
        follower = PurePursuit(lookahead_m=cfg.lookahead_m, max_speed_m_s=max_speed,
                               max_yaw_rate_rad_s=max_yaw,
                               turn_in_place_rad=math.radians(cfg.turn_in_place_deg))
        self._say(f"robot '{robot}' ({prof.name}), base '{base_body}', camera '{cam['name']}' "
                  f"{cam['width']}x{cam['height']}, {n_steps} steps of {dt} s per period, "
                  f"grid {grid.nx}x{grid.ny} at {grid.resolution_m} m, goal {goal.tolist()}")

        path = None
        first_plan_length = None
        last_plan = -10 ** 9
        replans = plan_failures = periods = 0
        travelled = 0.0
        twist = (0.0, 0.0)
        reason = None
        time_to_goal = None
        fall = None
        t = 0.0
        r = None
        c.twist(0.0, 0.0, 0.0, robot=robot)
        while reason is None:
            try:
                r = c.step(n_steps)
            except RunEndedError:
                reason = "run_ended"
                break
            periods += 1
            t = r.time_sec - t0
            gt = r.latest(GROUND_TRUTH_TOPIC)
            pose = base_pose_from_ground_truth(gt.header, base_body) if gt else None
            if pose is None:
                pose = base_pose_from_state(c.get_state(), info, base_body)
            new_xyz, q = pose
            travelled += float(np.hypot(*(new_xyz[:2] - xyz[:2])))
            xyz = new_xyz
            xy = xyz[:2]
            yaw = yaw_of(q)
            for m in r.by_topic(CONTACTS_TOPIC):
                contact_log.add(m.header)
            d_goal = float(np.hypot(*(goal - xy)))
            roll, pitch = roll_pitch_of(q)

            if d_goal <= cfg.goal_radius_m:
                reason, time_to_goal = "goal_reached", t
                break
            if (xyz[2] < prof.fall_height_m or abs(math.degrees(roll)) > prof.max_tilt_deg or
                    abs(math.degrees(pitch)) > prof.max_tilt_deg):
                reason = "fall"
                fall = {"base_z_m": float(xyz[2]), "roll_deg": math.degrees(roll),
                        "pitch_deg": math.degrees(pitch)}
                break
            if t >= cfg.timeout_sec - 1e-9:
                reason = "timeout"
                break
            if r.ended:
                reason = "run_ended"
                break

            frame = r.latest(depth_topic)
            if frame is not None:
                floor_z = cfg.floor_z if cfg.floor_z is not None else xyz[2] - prof.base_height_m
                h = frame.header
                grid.update_from_depth(frame.image(), h["fx"], h["fy"], h["cx"], h["cy"],
                                       camera_pose(h, xyz, q, prof), floor_z=floor_z,
                                       clearance_m=prof.clearance_m,
                                       robot_height_m=prof.height_m,
                                       max_range_m=cfg.max_range_m, stride=stride)
            cost_map = planner.cost_map(grid)

            blocked = None
            if path is not None:
                blocked = planner.first_blocked(path, grid, cost_map, skip_radius_m=radius,
                                                from_xy=xy,
                                                start_index=follower.progress_index)
            if path is None or blocked is not None or periods - last_plan >= cfg.replan_every:
                last_plan = periods
                replans += 1
                try:
                    new_path = planner.plan(grid, xy, goal,
                                            goal_tolerance_m=0.5 * cfg.goal_radius_m,
                                            cost_map=cost_map)
                except ValueError:
                    new_path = None
                if new_path is None:
                    plan_failures += 1
                    if blocked is not None:
                        path = None
                else:
                    path = new_path
                    follower.set_path(path)
                    if first_plan_length is None:
                        first_plan_length = path_length(path)
            self.path = path
            if path is None:
                twist = (0.0, cfg.search_yaw_rate_rad_s)
            else:
                twist = follower.command(xy, yaw)
            c.twist(twist[0], 0.0, twist[1], robot=robot)

            if self.trace is not None:
                self.trace.write(json.dumps({
                    "time_sec": r.time_sec, "xy": xy.tolist(), "yaw_rad": yaw,
                    "goal_distance_m": d_goal, "vx": twist[0], "yaw_rate": twist[1],
                    "replanned": last_plan == periods, "blocked_index": blocked,
                    "path_points": 0 if path is None else len(path)}) + "\n")
            if periods % max(1, int(round(1.0 / (n_steps * dt)))) == 0:
                self._say(f"t {t:6.2f} s  xy ({xy[0]:6.2f}, {xy[1]:6.2f})  yaw "
                          f"{math.degrees(yaw):7.1f} deg  goal {d_goal:5.2f} m  twist "
                          f"({twist[0]:.2f} m/s, {twist[1]:+.2f} rad/s)")

        try:
            c.twist(0.0, 0.0, 0.0, robot=robot)
        except RunEndedError:
            pass
        final_xy = xyz[:2]
        episode = {
            "success": reason == "goal_reached",
            "reason": reason,
            "time_to_goal_sec": time_to_goal,
            "episode_time_sec": t,
            "final_goal_distance_m": float(np.hypot(*(goal - final_xy))),
            "path_length_m": travelled,
            "planned_path_length_m": first_plan_length,
            "steps": periods,
            "physics_steps": (r.step - step0) if r is not None else 0,
            "goal_xy": goal.tolist(),
            "goal_radius_m": cfg.goal_radius_m,
            "timeout_sec": cfg.timeout_sec,
            "start_xy": start_xy.tolist(),
            "final_xy": final_xy.tolist(),
            "final_yaw_rad": yaw_of(q),
            "start_time_sec": t0,
            "end_time_sec": t0 + t,
            "robot": prof.name,
            "robot_name": robot,
            "base_body": base_body,
            "camera": cam["name"],
            "control_period_sec": n_steps * dt,
            "physics_steps_per_period": n_steps,
            "replans": replans,
            "plan_failures": plan_failures,
            "fall": fall,
            "contacts": contact_log.summary() if cfg.log_contacts else None,
            "contact_messages": contact_log.messages,
            "wall_time_sec": time.monotonic() - wall0,
            "config": asdict(cfg),
        }
        self._say(f"{reason}: {episode['final_goal_distance_m']:.2f} m from the goal after "
                  f"{t:.2f} s of sim time, {travelled:.2f} m travelled")
        return episode


def write_episode(episode, path):
    """Writes the episode dict as JSON to ``path`` ('-' = stdout)."""
    text = json.dumps(episode, indent=2, sort_keys=False)
    if path == "-":
        sys.stdout.write(text + "\n")
    else:
        with open(path, "w") as f:
            f.write(text + "\n")
