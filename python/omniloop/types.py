"""The shapes of the dicts omniloop gives, for type checkers and editors.

These are ``TypedDict``\\ s: at run time the values are plain ``dict``\\ s, so they cost nothing;
annotate with them (``truth: omniloop.types.Truth = sim.truth()``) to have the keys checked.
Dicts whose keys depend on the scenario or the experiment (``summary()``, ``record()``,
``camera_model()``, ``dataset.json``) stay ``dict[str, Any]``.
"""

from __future__ import annotations

from typing import Dict, List, Optional, Tuple, TypedDict

import numpy as np
import numpy.typing as npt

__all__ = [
    "Ball",
    "Differential",
    "Dribble",
    "FreeSpace",
    "Goal",
    "Kick",
    "KickerInfo",
    "LegendEntry",
    "OdometryErrors",
    "PanAt",
    "PanTo",
    "RobotInfo",
    "SensorInfo",
    "Trajectory",
    "Truth",
    "TruthFrame",
]


class Ball(TypedDict):
    """The ball now (``Simulation.truth()["ball"]``): the simulator's side."""

    x_mm: float
    y_mm: float
    #: Height of its centre above the floor (its radius on the floor).
    z_mm: float
    vx_mm_s: float
    vy_mm_s: float
    vz_mm_s: float


class _BallKeys(TypedDict, total=False):
    #: With a ball: the ball.
    ball: Ball
    #: With a ball: whether it is at this robot's dribbler, where its light barrier sees it.
    ball_in_dribbler: bool


class Truth(_BallKeys):
    """The truth of one robot now (``Simulation.truth()``): the simulator's side."""

    t_s: float
    x_mm: float
    y_mm: float
    theta_rad: float
    #: World-frame velocity, mm/s.
    vx_mm_s: float
    vy_mm_s: float
    omega_rad_s: float
    #: Contacts so far.
    contacts: int
    reached_goal: bool
    #: Waypoints reached (``None`` without waypoints).
    targets_reached: Optional[int]


#: One label of a truth frame, as ``legend.json`` holds it (``class`` is a Python keyword,
#: hence the functional form).
LegendEntry = TypedDict(
    "LegendEntry",
    {"label": int, "class": str, "instance": int, "name": str, "rgb": List[int]},
)


class TruthFrame(TypedDict):
    """The truth beside one frame (``Simulation.truth_frames()``), each array ``H x W``."""

    #: How far the light travelled to the camera, mirror included; inf for the sky, NaN where
    #: the pixel sees no mirror.
    depth_mm: npt.NDArray[np.float32]
    #: The floor point's distance from the robot's centre where the pixel shows the floor.
    floor_mm: npt.NDArray[np.float32]
    #: What the pixel shows (a ``legend`` entry's ``label``).
    labels: npt.NDArray[np.uint16]
    legend: List[LegendEntry]


class FreeSpace(TypedDict):
    """The free space of a frame (``FreeSpaceDetector.detect``)."""

    #: Each direction's centre angle in the robot frame.
    direction_rad: npt.NDArray[np.float64]
    #: Distance from the sensor axis to the first obstacle cell (or the template's edge).
    free_mm: npt.NDArray[np.float64]
    #: Surely free.
    clear_mm: npt.NDArray[np.float64]
    #: Farthest the obstacle's face can be.
    front_mm: npt.NDArray[np.float64]
    #: The template's outer edge on the floor.
    range_mm: float
    #: The template's inner edge on the floor.
    inner_mm: float
    #: The sensor axis in the robot frame, the origin of the distances.
    axis_mm: Tuple[float, float]


class Differential(TypedDict):
    """A differential drive (``RobotInfo["differential"]``)."""

    track_mm: float
    max_turn_rate_rad_s: float


class SensorInfo(TypedDict):
    """One camera of a robot (``RobotInfo["sensors"]``)."""

    name: str
    width_px: int
    height_px: int
    #: The optics' kind (``"hyperbolic"``, ``"pinhole"``, ...).
    kind: str
    #: Whether a pan unit turns it.
    pan_unit: bool


class OdometryErrors(TypedDict):
    """The wheel odometry's errors (``RobotInfo["odometry"]``)."""

    speed_noise_frac: float
    omega_noise_rad_s: float
    scale_bias_frac: float
    omega_bias_rad_s: float
    slip_s: float


class Goal(TypedDict):
    """The goal (``RobotInfo["goal"]``)."""

    x_mm: float
    y_mm: float
    tolerance_mm: float
    #: Waypoints before it, ``[x_mm, y_mm]`` each.
    waypoints_mm: List[List[float]]


class KickerInfo(TypedDict):
    """A robot's kicker and dribbler (``RobotInfo["kicker"]``)."""

    #: The fastest kick, mm/s.
    max_kick_mm_s: float
    #: The dribbler speed of its full pull, rpm.
    full_pull_rpm: float
    #: The flat front's distance from the centre, mm.
    front_mm: float


class RobotInfo(TypedDict):
    """What a robot knows of itself (``Scenario.robot``, ``Scenario.robots``)."""

    name: str
    #: ``(x_mm, y_mm, theta_rad)``.
    start: Tuple[float, float, float]
    radius_mm: float
    max_speed_mm_s: float
    accel_limit_mm_s2: float
    angular_accel_limit_rad_s2: float
    differential: Optional[Differential]
    #: Its kicker and dribbler (``[robot.kicker]``), if it has them.
    kicker: Optional[KickerInfo]
    sensors: List[SensorInfo]
    odometry: OdometryErrors
    goal: Optional[Goal]


#: A trajectory as columns named as ``trajectory.csv``'s header (``t_s``, ``x_mm``, ...,
#: ``est_theta_rad``), ``float64`` each (NaN where empty).
Trajectory = Dict[str, npt.NDArray[np.float64]]


class PanTo(TypedDict):
    """A pan command: turn camera ``sensor`` toward ``pan_rad`` (``Simulation.step``)."""

    sensor: str
    pan_rad: float


class PanAt(TypedDict):
    """A pan command: turn camera ``sensor`` at ``rate_rad_s`` until told otherwise."""

    sensor: str
    rate_rad_s: float


class _KickAngle(TypedDict, total=False):
    angle_rad: float


class Kick(_KickAngle):
    """A kick (``Simulation.step``): armed until the ball is at the dribbler, then fired once at
    ``kick_mm_s`` (at most the kicker's limit; 0 disarms), ``angle_rad`` above the floor (0 a
    flat kick, above 0 a chip)."""

    kick_mm_s: float


class Dribble(TypedDict):
    """The dribbler's speed (``Simulation.step``), rpm (0: off), until told otherwise."""

    dribbler_rpm: float
