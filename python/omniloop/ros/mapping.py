"""What omniloop's values become on ROS 2 topics, with no ROS import: SI units and REP-103 axes,
stamps, the odometry's covariance, the free space as a laser scan, a camera model as
``camera_info`` fields, ``cmd_vel`` checked and clipped to the robot's limits, the kicker's and
the dribbler's commands checked, and the ball's truth.

omniloop works in millimetres, seconds and radians, x forward, y left, z up (REP-103's body
axes); ROS in metres. Every function here is plain arithmetic, tested without ROS 2.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, List, Mapping, Optional, Sequence, Tuple

import numpy as np

from ..types import Ball, Dribble, Kick

MM = 1e-3
"""Metres in a millimetre."""

PLANAR_VARIANCE = 1e-9
"""The variance given to z, roll and pitch and their rates: the robot moves on the floor, so
they are known to be zero (a covariance of exactly 0 reads as "not measured" to some tools)."""

OMNIDIR_MODEL = "omnidir_mei"
"""``CameraInfo.distortion_model`` of a mirror camera: Mei's unified model as OpenCV's
``cv::omnidir`` takes it, ``d = [k1, k2, p1, p2, xi]`` (ROS has no standard name for it). The
first four are in plumb_bob's places; ``xi`` is the unit sphere's offset. ``k`` is ``K`` of
``cv::omnidir``, ``p`` is ``[K | 0]``."""


def stamp(t_s: float) -> Tuple[int, int]:
    """Simulation time ``t_s`` as ``builtin_interfaces/Time``'s ``(sec, nanosec)``, to the
    nearest nanosecond."""
    ns = round(t_s * 1e9)
    return ns // 1_000_000_000, ns % 1_000_000_000


def seconds(sec: int, nanosec: int) -> float:
    """A ``builtin_interfaces/Time`` as seconds."""
    return sec + nanosec * 1e-9


def yaw_quaternion(theta_rad: float) -> Tuple[float, float, float, float]:
    """A rotation by ``theta_rad`` about z as a quaternion ``(x, y, z, w)``."""
    return 0.0, 0.0, math.sin(0.5 * theta_rad), math.cos(0.5 * theta_rad)


def matrix_quaternion(r: Sequence[Sequence[float]]) -> Tuple[float, float, float, float]:
    """A rotation matrix (rows) as a unit quaternion ``(x, y, z, w)`` (Shepperd's method)."""
    m = np.asarray(r, dtype=float)
    trace = m[0, 0] + m[1, 1] + m[2, 2]
    if trace > 0.0:
        s = 2.0 * math.sqrt(1.0 + trace)
        q = ((m[2, 1] - m[1, 2]) / s, (m[0, 2] - m[2, 0]) / s, (m[1, 0] - m[0, 1]) / s, 0.25 * s)
    elif m[0, 0] > m[1, 1] and m[0, 0] > m[2, 2]:
        s = 2.0 * math.sqrt(1.0 + m[0, 0] - m[1, 1] - m[2, 2])
        q = (0.25 * s, (m[0, 1] + m[1, 0]) / s, (m[0, 2] + m[2, 0]) / s, (m[2, 1] - m[1, 2]) / s)
    elif m[1, 1] > m[2, 2]:
        s = 2.0 * math.sqrt(1.0 + m[1, 1] - m[0, 0] - m[2, 2])
        q = ((m[0, 1] + m[1, 0]) / s, 0.25 * s, (m[1, 2] + m[2, 1]) / s, (m[0, 2] - m[2, 0]) / s)
    else:
        s = 2.0 * math.sqrt(1.0 + m[2, 2] - m[0, 0] - m[1, 1])
        q = ((m[0, 2] + m[2, 0]) / s, (m[1, 2] + m[2, 1]) / s, 0.25 * s, (m[1, 0] - m[0, 1]) / s)
    n = math.sqrt(sum(c * c for c in q))
    return tuple(c / n for c in q)  # type: ignore[return-value]


def panned(rotation: Sequence[Sequence[float]], pan_rad: float) -> List[List[float]]:
    """A camera's frame in the body frame (``rotation``, its axes as columns, at pan 0) turned
    by its pan unit through ``pan_rad`` about the body's z axis."""
    c, s = math.cos(pan_rad), math.sin(pan_rad)
    rz = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
    turned: List[List[float]] = (rz @ np.asarray(rotation, dtype=float)).tolist()
    return turned


@dataclass
class OdometryCovariance:
    """The covariance of the integrated wheel odometry, propagated a reading at a time from the
    scenario's ``[odometry]`` errors.

    A reading's error (body frame): each velocity component has standard deviation
    ``|v| sqrt(speed_noise_frac^2 + scale_bias_frac^2)``, the rotation rate
    ``sqrt(omega_noise_rad_s^2 + omega_bias_rad_s^2)``: the noise and the systematic error
    (whose sign the robot does not know) together. Integration (first order, the heading before
    the step): ``x' = x + R(theta) v dt``, ``theta' = theta + omega dt``, so
    ``P' = F P F^T + G Q G^T`` with ``F = d(x', y', theta') / d(x, y, theta)``,
    ``G = d(x', y', theta') / d(vx, vy, omega)``. Each reading's error is taken as independent
    of the last: a bias grows the true error as ``t`` where this grows it as ``sqrt(t)``, and the
    slip (``slip_s``), which depends on the acceleration, is left out.
    """

    speed_frac: float
    omega_rad_s: float
    pose: np.ndarray = field(default_factory=lambda: np.zeros((3, 3)))
    """Covariance of ``(x_m, y_m, theta_rad)``."""
    twist: np.ndarray = field(default_factory=lambda: np.zeros(3))
    """Variances of the last reading's ``(vx_m_s, vy_m_s, omega_rad_s)``."""

    @classmethod
    def from_spec(cls, spec: Mapping[str, Any]) -> "OdometryCovariance":
        """From a robot's ``odometry`` dict (``Scenario.robot["odometry"]``)."""
        return cls(
            speed_frac=math.hypot(spec["speed_noise_frac"], spec["scale_bias_frac"]),
            omega_rad_s=math.hypot(spec["omega_noise_rad_s"], spec["omega_bias_rad_s"]),
        )

    def reset(self) -> None:
        """Back to the start, where the pose is known exactly."""
        self.pose = np.zeros((3, 3))
        self.twist = np.zeros(3)

    def update(
        self, vx_mm_s: float, vy_mm_s: float, omega_rad_s: float, dt_s: float, theta_rad: float
    ) -> None:
        """Adds the reading ``(vx, vy, omega)`` over ``dt_s``, taken at heading ``theta_rad``."""
        vx, vy = vx_mm_s * MM, vy_mm_s * MM
        qx, qy, qw = (self.speed_frac * vx) ** 2, (self.speed_frac * vy) ** 2, self.omega_rad_s**2
        self.twist = np.array([qx, qy, qw])
        if dt_s <= 0.0:
            return
        c, s = math.cos(theta_rad), math.sin(theta_rad)
        # F = [[1, 0, a], [0, 1, b], [0, 0, 1]]; G Q G^T, G = [[c dt, -s dt, 0], [s dt, c dt, 0],
        # [0, 0, dt]]: written out, a cycle's few numbers cost less than NumPy's calls.
        a, b = (-s * vx - c * vy) * dt_s, (c * vx - s * vy) * dt_s
        (p00, p01, p02), (_, p11, p12), (_, _, p22) = self.pose.tolist()
        f02, f12 = p02 + a * p22, p12 + b * p22
        d2 = dt_s * dt_s
        n00 = p00 + 2 * a * p02 + a * a * p22 + d2 * (c * c * qx + s * s * qy)
        n01 = p01 + a * p12 + b * p02 + a * b * p22 + d2 * c * s * (qx - qy)
        n11 = p11 + 2 * b * p12 + b * b * p22 + d2 * (s * s * qx + c * c * qy)
        n22 = p22 + d2 * qw
        self.pose = np.array([[n00, n01, f02], [n01, n11, f12], [f02, f12, n22]])

    def pose_6x6(self) -> List[float]:
        """The pose covariance as ``nav_msgs/Odometry`` takes it (row-major 6 x 6 over x, y, z,
        roll, pitch, yaw)."""
        return _six(self.pose.tolist())

    def twist_6x6(self) -> List[float]:
        """The twist covariance as ``nav_msgs/Odometry`` takes it."""
        qx, qy, qw = self.twist.tolist()
        return _six([[qx, 0.0, 0.0], [0.0, qy, 0.0], [0.0, 0.0, qw]])


def _six(p3: List[List[float]]) -> List[float]:
    """A covariance over ``(x, y, yaw)`` spread over the 6 x 6 of ``(x, y, z, roll, pitch,
    yaw)``, the planar axes known."""
    out = [0.0] * 36
    for k in (2, 3, 4):
        out[7 * k] = PLANAR_VARIANCE
    for i, a in enumerate((0, 1, 5)):
        for j, b in enumerate((0, 1, 5)):
            out[6 * a + b] = p3[i][j]
    return out


@dataclass(frozen=True)
class Scan:
    """A ``sensor_msgs/LaserScan``'s numbers, metres and radians."""

    angle_min: float
    angle_max: float
    angle_increment: float
    range_min: float
    range_max: float
    ranges: List[float]


def free_space_scan(free: Mapping[str, Any]) -> Scan:
    """The free space of a frame (``FreeSpaceDetector.detect``) as a laser scan about the
    sensor's axis: one beam a direction of the polar template, at the direction's centre angle
    (``2 pi j / J`` in the robot frame); its range the free distance to the first obstacle cell,
    ``+inf`` where the direction is free to the template's edge (REP-117: nothing detected
    within ``range_max``). ``range_min`` is the template's inner edge (the robot's blind zone);
    a direction blocked in its first ring reads ``range_min``."""
    angles, free_mm = free["direction_rad"], free["free_mm"]
    n = len(angles)
    increment = 2.0 * math.pi / n
    reach = float(free["range_mm"])
    return Scan(
        angle_min=float(angles[0]),
        angle_max=float(angles[0] + (n - 1) * increment),
        angle_increment=increment,
        range_min=float(free["inner_mm"]) * MM,
        range_max=reach * MM,
        ranges=[math.inf if d >= reach - 1e-6 else d * MM for d in free_mm.tolist()],
    )


@dataclass(frozen=True)
class CameraInfo:
    """A ``sensor_msgs/CameraInfo``'s numbers."""

    width: int
    height: int
    distortion_model: str
    d: List[float]
    k: List[float]
    r: List[float]
    p: List[float]


def camera_info(model: Mapping[str, Any]) -> CameraInfo:
    """A camera model (``Scenario.camera_model``) as ``camera_info``: a pinhole camera's ``K``
    with no distortion (``plumb_bob``, zeros); a mirror camera's fitted unified model as
    :data:`OMNIDIR_MODEL`."""
    w, h = model["image_size_px"]
    intr = model["intrinsics"]
    (fx, fy), (cx, cy) = intr["focal_px"], intr["principal_point_px"]
    skew = intr.get("skew_px", 0.0)
    k = [fx, skew, cx, 0.0, fy, cy, 0.0, 0.0, 1.0]
    if intr["model"] == "pinhole":
        name, d = "plumb_bob", [0.0] * 5
    else:
        name, d = OMNIDIR_MODEL, list(intr["distortion_k1_k2_p1_p2"]) + [intr["xi"]]
    return CameraInfo(
        width=int(w),
        height=int(h),
        distortion_model=name,
        d=[float(x) for x in d],
        k=[float(x) for x in k],
        r=[1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0],
        p=[fx, skew, cx, 0.0, 0.0, fy, cy, 0.0, 0.0, 0.0, 1.0, 0.0],
    )


def command_at(
    command: Tuple[float, ...],
    received_t_s: float,
    t_s: float,
    timeout_s: float,
    stop: Tuple[float, ...],
) -> Tuple[float, ...]:
    """The command to apply at simulation time ``t_s``: ``command`` (received at
    ``received_t_s``), or ``stop`` once it is older than ``timeout_s``."""
    return stop if t_s - received_t_s > timeout_s + 1e-9 else command


class CommandError(ValueError):
    """A command the robot cannot take: a ``cmd_vel`` with a number that is not finite, a kick
    its kicker cannot fire, a dribbler speed below 0, a kick or dribbler command to a robot
    without them."""


def body_command(
    linear_x: float,
    linear_y: float,
    angular_z: float,
    robot: Mapping[str, Any],
) -> Tuple[float, ...]:
    """A ``cmd_vel`` (m/s, rad/s, body frame) as the command ``Simulation.step`` takes,
    clipped to ``robot``'s limits (``Scenario.robot``): the speed to ``max_speed_mm_s`` (the
    direction kept); a differential robot takes ``(v_mm_s, omega_rad_s)``, ``linear_y``
    dropped, the turn rate clipped to its ``max_turn_rate_rad_s``. Raises
    :class:`CommandError` for a number that is not finite."""
    values = (linear_x, linear_y, angular_z)
    if not all(math.isfinite(v) for v in values):
        raise CommandError(
            f"cmd_vel is not finite: linear ({linear_x}, {linear_y}), angular.z {angular_z}"
        )
    vmax = float(robot["max_speed_mm_s"])
    vx, vy = linear_x / MM, linear_y / MM
    diff: Optional[Mapping[str, Any]] = robot.get("differential")
    if diff is not None:
        vy = 0.0
    speed = math.hypot(vx, vy)
    if speed > vmax:
        vx, vy = vx * vmax / speed, vy * vmax / speed
    if diff is not None:
        wmax = float(diff["max_turn_rate_rad_s"])
        return vx, max(-wmax, min(wmax, angular_z))
    return vx, vy, angular_z


KICK_ASIDE_M_S = 1e-6
"""The most a kick's ``y`` (m/s) may differ from 0: the kicker fires along the robot's
heading, so a kick aside is a command it cannot take, rounding aside."""


def kick_command(
    x_m_s: float, y_m_s: float, z_m_s: float, kicker: Optional[Mapping[str, Any]]
) -> Kick:
    """A ``kick`` (``geometry_msgs/Vector3``: the velocity the kicker gives the ball in
    ``base_link``, m/s: ``x`` forward, ``z`` up, ``y`` 0) as the actuator command
    ``Simulation.step`` takes: ``{"kick_mm_s": S, "angle_rad": A}``, ``S`` its norm in mm/s and
    ``A`` its angle above the floor (``z = 0``: a flat kick; ``z > 0``: a chip; all 0: disarm).
    ``kicker`` is the robot's (``Scenario.robot["kicker"]``). Raises :class:`CommandError`
    without a kicker, for a number that is not finite, a kick backward, down or aside, or
    one over ``max_kick_mm_s`` (a speed over it by rounding alone is taken as the limit)."""
    if kicker is None:
        raise CommandError("kick: the robot has no kicker ([robot.kicker])")
    if not all(math.isfinite(v) for v in (x_m_s, y_m_s, z_m_s)):
        raise CommandError(f"kick is not finite: ({x_m_s}, {y_m_s}, {z_m_s}) m/s")
    if x_m_s < 0.0 or z_m_s < 0.0 or abs(y_m_s) > KICK_ASIDE_M_S:
        raise CommandError(
            f"kick ({x_m_s}, {y_m_s}, {z_m_s}) m/s: the kicker fires forward (x > 0) and up "
            "(z >= 0), never back, down or aside (y = 0)"
        )
    speed = math.hypot(x_m_s, z_m_s) / MM
    if speed == 0.0:
        return Kick(kick_mm_s=0.0, angle_rad=0.0)
    angle = math.atan2(z_m_s, x_m_s)
    if not angle < 0.5 * math.pi:
        raise CommandError(f"kick ({x_m_s}, {y_m_s}, {z_m_s}) m/s: straight up is no kick")
    limit = float(kicker["max_kick_mm_s"])
    if speed > limit * (1.0 + 1e-9):
        raise CommandError(
            f"kick speed {speed * MM:g} m/s is over the kicker's limit of {limit * MM:g} m/s"
        )
    return Kick(kick_mm_s=min(speed, limit), angle_rad=angle)


def dribbler_command(rpm: float, kicker: Optional[Mapping[str, Any]]) -> Dribble:
    """A ``dribbler`` speed (``std_msgs/Float32``, rpm; 0 stops it) as the actuator command
    ``Simulation.step`` takes: ``{"dribbler_rpm": R}``. Raises :class:`CommandError` without
    a dribbler, or for a speed that is not a finite number >= 0."""
    if kicker is None:
        raise CommandError("dribbler: the robot has no dribbler ([robot.kicker])")
    if not (math.isfinite(rpm) and rpm >= 0.0):
        raise CommandError(f"dribbler speed {rpm} rpm: it must be a finite number >= 0")
    return Dribble(dribbler_rpm=float(rpm))


@dataclass(frozen=True)
class BallState:
    """The ball's truth as the ``/ground_truth/ball`` odometry takes it: metres, m/s, in
    ``map`` (the ball's frame parallel to it, so the velocity is the same in both)."""

    position: Tuple[float, float, float]
    velocity: Tuple[float, float, float]


def ball_state(ball: Ball) -> BallState:
    """``Simulation.truth()["ball"]`` (mm, mm/s; ``z_mm`` its centre's height) in metres."""
    return BallState(
        position=(ball["x_mm"] * MM, ball["y_mm"] * MM, ball["z_mm"] * MM),
        velocity=(ball["vx_mm_s"] * MM, ball["vy_mm_s"] * MM, ball["vz_mm_s"] * MM),
    )
