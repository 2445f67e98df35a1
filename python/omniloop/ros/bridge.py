"""The ROS 2 node: one simulation, each robot's sensors on topics under its name, its
``cmd_vel`` in, ``/clock`` and every stamp on simulation time.

Per robot, under its name (``NS``): ``SENSOR/image_raw`` and ``SENSOR/camera_info`` of each
camera, ``odom`` (wheel odometry, integrated), ``scan`` (the floor's free space as a
``LaserScan``), ``goal_pose`` (latched), ``ground_truth/odom`` (for scoring only) and
``cmd_vel`` in; with a kicker (``[robot.kicker]``) also ``ball_in_dribbler`` (the light
barrier) and ``kick`` and ``dribbler`` in; ``/clock``, and with a ball ``/ground_truth/ball``
(for scoring only). docs/ros.md has the table, the frames and the camera model.

A cycle's messages share its stamp; ``odom`` is the last of the robot's (the truth follows it),
so that a node answering it answers the cycle. The odometry's frame ``odom`` coincides with
``map`` (the field) at the start, where the robot is told it starts; ``/tf`` (``odom ->
base_link -> SENSOR_optical, SENSOR_scan``) is published where ``tf2_msgs`` can be imported.
Services ``~/reset`` (``std_srvs/Trigger``, seed from the ``seed`` parameter), ``~/pause``
(``std_srvs/SetBool``) and ``~/step`` (``std_srvs/Trigger``).
"""

from __future__ import annotations

import array
import dataclasses
import math
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable, Dict, List, Optional, Sequence, Tuple, Union, cast

import numpy as np
import numpy.typing as npt
import rclpy
from builtin_interfaces.msg import Time
from geometry_msgs.msg import PoseStamped, Twist, TwistStamped, Vector3
from nav_msgs.msg import Odometry
from rcl_interfaces.msg import SetParametersResult
from rclpy.duration import Duration
from rclpy.executors import SingleThreadedExecutor
from rclpy.node import Node
from rclpy.parameter import Parameter
from rclpy.publisher import Publisher
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
from rclpy.subscription import Subscription
from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import CameraInfo, Image, LaserScan
from std_msgs.msg import Bool, Float32
from std_srvs.srv import SetBool, Trigger

import omniloop
from omniloop._omniloop import FreeSpaceDetector
from omniloop.types import Ball, Dribble, FreeSpace, Kick, KickerInfo, Truth

from . import mapping
from .mapping import MM, CommandError, OdometryCovariance

try:  # tf2_msgs has no wheel on the package index: /tf only with a ROS 2 installation.
    from geometry_msgs.msg import TransformStamped
    from tf2_msgs.msg import TFMessage
except ImportError:
    TFMessage = None

Actuator = Union[Kick, Dribble]
"""A kicker's or dribbler's command as ``Simulation.step`` takes it."""

RELIABLE = QoSProfile(depth=5, reliability=ReliabilityPolicy.RELIABLE)
LATCHED = QoSProfile(
    depth=1, reliability=ReliabilityPolicy.RELIABLE, durability=DurabilityPolicy.TRANSIENT_LOCAL
)


@dataclass
class BridgeOptions:
    """How the node runs a scenario."""

    lockstep: bool = False
    """Each cycle waits for every driven robot's command answering its last frame."""
    realtime_factor: float = 1.0
    """Without lockstep: simulation seconds per wall second (0: as fast as it goes)."""
    robot: str = "python"
    """``python``: the robots take ``cmd_vel``; ``builtin``: omniloop's own software drives;
    ``ssl``: a Small-Size team's AI drives them over the SSL simulation protocol."""
    seed: Optional[int] = None
    renderer: str = "cpu"
    twist_stamped: bool = False
    """``cmd_vel`` is ``geometry_msgs/TwistStamped`` (else ``Twist``)."""
    cmd_vel_timeout_s: float = 0.5
    """A command older than this (simulation time) stops the robot."""
    lockstep_timeout_s: float = 10.0
    """Wall seconds a lockstep cycle waits for its commands before going on without them."""
    out: Optional[Path] = None
    """Where the run's files go when it ends (``omniloop run``'s)."""
    exit_at_end: bool = False
    """Exit when the run is over (else wait for ``~/reset``)."""
    progress_s: float = 5.0
    """A progress line every this many simulation seconds (0: none)."""


def time_msg(t_s: float) -> Time:
    sec, nanosec = mapping.stamp(t_s)
    return Time(sec=sec, nanosec=nanosec)


class RobotPort:
    """One robot's publishers, its ``cmd_vel`` (with a kicker, its ``kick`` and ``dribbler``)
    and what the robot's side keeps between cycles (its detector, its odometry's covariance,
    its last command, the kicker's and dribbler's commands not yet applied)."""

    def __init__(self, bridge: "Bridge", name: str, ns: str, prefix: str) -> None:
        node, scenario = bridge.node, bridge.scenario
        self.bridge = bridge
        self.name, self.ns, self.prefix = name, ns, prefix
        self.spec = scenario.robots[name]
        self.sensors = [s["name"] for s in self.spec["sensors"]]
        self.models = {s: scenario.camera_model(s, robot=name) for s in self.sensors}

        def topic(t: str) -> str:
            return f"/{ns}/{t}"

        self.images = {
            s: node.create_publisher(Image, topic(f"{s}/image_raw"), RELIABLE) for s in self.sensors
        }
        self.info_pubs = {
            s: node.create_publisher(CameraInfo, topic(f"{s}/camera_info"), RELIABLE)
            for s in self.sensors
        }
        self.odom = node.create_publisher(Odometry, topic("odom"), RELIABLE)
        self.truth = node.create_publisher(Odometry, topic("ground_truth/odom"), RELIABLE)
        self.goal = node.create_publisher(PoseStamped, topic("goal_pose"), LATCHED)
        # Each topic's message, built once: a cycle sets what changes.
        self.image_msgs = {s: Image(encoding="rgb8", is_bigendian=0) for s in self.sensors}
        self.info_msgs = {s: camera_info_msg(self.models[s]) for s in self.sensors}
        for s in self.sensors:
            self.image_msgs[s].header.frame_id = self.info_msgs[s].header.frame_id = self.frame(
                f"{s}_optical"
            )
        self.odom_msg = odometry_frames(self.frame("odom"), self.frame("base_link"))
        self.truth_msg = odometry_frames("map", self.frame("base_link"))
        self.scan_msg = LaserScan(time_increment=0.0, scan_time=scenario.control_period_s)
        self.scan: Optional[Publisher[LaserScan]] = None
        self.detector: Optional[FreeSpaceDetector] = None
        self.scan_sensor: Optional[str] = None
        self.scan_axis_mm = (0.0, 0.0)
        self.covariance = OdometryCovariance.from_spec(self.spec["odometry"])
        self.command: Tuple[float, ...] = self.stop()
        self.command_t_s = -math.inf
        self.command_stamp = -math.inf
        self.awaiting_t_s: Optional[float] = None
        self.cmd_vel: Optional[Subscription[Any]] = None
        if bridge.options.robot == "python":
            kind = TwistStamped if bridge.options.twist_stamped else Twist
            self.cmd_vel = node.create_subscription(
                kind, topic("cmd_vel"), self.on_cmd_vel, RELIABLE
            )
        self.kicker: Optional[KickerInfo] = self.spec["kicker"]
        self.barrier: Optional[Publisher[Bool]] = None
        self.ball_subs: List[Subscription[Any]] = []
        self.pending: Dict[str, Actuator] = {}
        if self.kicker is not None:
            self.ball_topics(node, topic)

    def ball_topics(self, node: Node, topic: Callable[[str], str]) -> None:
        """A kicker's topics: the light barrier out, and (where Python drives) the kick and the
        dribbler's speed in."""
        self.barrier = node.create_publisher(Bool, topic("ball_in_dribbler"), RELIABLE)
        if self.bridge.options.robot != "python":
            return
        self.ball_subs = [
            node.create_subscription(Vector3, topic("kick"), self.on_kick, RELIABLE),
            node.create_subscription(Float32, topic("dribbler"), self.on_dribbler, RELIABLE),
        ]

    def frame(self, name: str) -> str:
        return self.prefix + name

    def stop(self) -> Tuple[float, ...]:
        return (0.0, 0.0) if self.spec["differential"] else (0.0, 0.0, 0.0)

    def attach(self, sim: "omniloop.Simulation") -> None:
        """Starts a new episode of ``sim``: the covariance and the command afresh, and the
        detector of its free space."""
        self.covariance.reset()
        self.command, self.command_t_s, self.command_stamp = self.stop(), -math.inf, -math.inf
        self.pending = {}
        try:
            detector = sim.free_space_detector(robot=self.name)
        except ValueError as e:
            if self.scan is None:
                self.bridge.node.get_logger().info(f"{self.ns}: no scan ({e})")
            self.detector = None
            return
        self.detector = detector
        self.scan_sensor = detector.camera
        self.scan_msg.header.frame_id = self.frame(f"{self.scan_sensor}_scan")
        if self.scan is None:
            self.scan = self.bridge.node.create_publisher(LaserScan, f"/{self.ns}/scan", RELIABLE)

    def on_cmd_vel(self, msg: Any) -> None:
        twist = msg.twist if self.bridge.options.twist_stamped else msg
        try:
            command = mapping.body_command(
                twist.linear.x, twist.linear.y, twist.angular.z, self.spec
            )
        except CommandError as e:
            self.bridge.node.get_logger().warning(
                f"{self.ns}: {e}: refused", throttle_duration_sec=1.0
            )
            return
        stamp = None
        if self.bridge.options.twist_stamped:
            stamp = mapping.seconds(msg.header.stamp.sec, msg.header.stamp.nanosec)
            if stamp < self.command_stamp:
                return  # an older command arriving late
            self.command_stamp = stamp
        self.command, self.command_t_s = command, self.bridge.t_s
        waiting = self.awaiting_t_s
        if waiting is not None and (stamp is None or stamp >= waiting - 1e-9):
            self.awaiting_t_s = None
            self.bridge.answered()

    def on_kick(self, msg: Vector3) -> None:
        """A kick, checked (a bad one refused with a warning, at most one a second): armed at
        the next cycle (the last kick of a cycle counts)."""
        try:
            self.pending["kick"] = mapping.kick_command(msg.x, msg.y, msg.z, self.kicker)
        except CommandError as e:
            self.bridge.node.get_logger().warning(
                f"{self.ns}: {e}: refused", throttle_duration_sec=1.0
            )

    def on_dribbler(self, msg: Float32) -> None:
        """The dribbler's speed, checked (a bad one refused with a warning, at most one a
        second): from the next cycle until told otherwise."""
        try:
            self.pending["dribbler"] = mapping.dribbler_command(msg.data, self.kicker)
        except CommandError as e:
            self.bridge.node.get_logger().warning(
                f"{self.ns}: {e}: refused", throttle_duration_sec=1.0
            )

    def take_actuators(self) -> Optional[List[Actuator]]:
        """The kicker's and dribbler's commands come since the last cycle (``None``: none),
        for ``Simulation.step``'s ``actuators``."""
        if not self.pending:
            return None
        out = list(self.pending.values())
        self.pending = {}
        return out

    def command_now(self, t_s: float) -> Tuple[float, ...]:
        """The command to apply at ``t_s``: the last, unless older than the timeout."""
        timeout = self.bridge.options.cmd_vel_timeout_s
        return mapping.command_at(self.command, self.command_t_s, t_s, timeout, self.stop())

    def publish(self, obs: omniloop.Observation, truth: Truth, t_s: float) -> None:
        """Publishes robot ``obs``'s frames, scan and odometry (last of its sensors), then the
        truth, stamped ``t_s``."""
        stamp = time_msg(t_s)
        for sensor, img in obs.frames.items():
            self.publish_frame(sensor, img, stamp)
        if self.detector is not None and self.scan_sensor in obs.frames:
            self.publish_scan(self.detector.detect(obs.frames[self.scan_sensor]), stamp)
        self.bridge.publish_tf(self, obs, stamp)
        if self.barrier is not None:
            self.barrier.publish(Bool(data=bool(obs.ball_in_dribbler)))
        # The odometry last: answering it answers the cycle.
        o = obs.odometry
        x, y, theta = obs.odometry_pose
        self.covariance.update(
            o.vx_mm_s, o.vy_mm_s, o.omega_rad_s, o.dt_s, theta - o.omega_rad_s * o.dt_s
        )
        msg = fill_odometry(
            self.odom_msg, stamp, (x, y, theta), (o.vx_mm_s, o.vy_mm_s, o.omega_rad_s)
        )
        msg.pose.covariance = self.covariance.pose_6x6()
        msg.twist.covariance = self.covariance.twist_6x6()
        self.odom.publish(msg)
        # The truth, in the map frame (the twist in the body frame, as Odometry has it): not
        # the robot's, so after its sensors.
        c, s = math.cos(truth["theta_rad"]), math.sin(truth["theta_rad"])
        vx, vy = truth["vx_mm_s"], truth["vy_mm_s"]
        body_v = (c * vx + s * vy, -s * vx + c * vy, truth["omega_rad_s"])
        pose = (truth["x_mm"], truth["y_mm"], truth["theta_rad"])
        self.truth.publish(fill_odometry(self.truth_msg, stamp, pose, body_v))

    def publish_frame(self, sensor: str, img: npt.NDArray[np.uint8], stamp: Time) -> None:
        msg, info = self.image_msgs[sensor], self.info_msgs[sensor]
        msg.header.stamp = info.header.stamp = stamp
        msg.height, msg.width = img.shape[0], img.shape[1]
        msg.step = 3 * img.shape[1]
        msg.data = array.array("B", img.tobytes())
        self.images[sensor].publish(msg)
        self.info_pubs[sensor].publish(info)

    def publish_scan(self, free: FreeSpace, stamp: Time) -> None:
        scan = mapping.free_space_scan(free)
        self.scan_axis_mm = free["axis_mm"]
        msg = self.scan_msg
        msg.angle_min, msg.angle_max, msg.angle_increment = (
            scan.angle_min,
            scan.angle_max,
            scan.angle_increment,
        )
        msg.range_min, msg.range_max = scan.range_min, scan.range_max
        msg.ranges = array.array("f", scan.ranges)
        msg.header.stamp = stamp
        if self.scan is not None:
            self.scan.publish(msg)

    def publish_goal(self) -> None:
        goal = self.spec.get("goal")
        if goal is None:
            return
        msg = PoseStamped()
        msg.header.frame_id = "map"
        msg.pose.position.x, msg.pose.position.y = goal["x_mm"] * MM, goal["y_mm"] * MM
        msg.pose.orientation.w = 1.0
        self.goal.publish(msg)


def odometry_frames(frame: str, child: str) -> Odometry:
    """An ``Odometry`` of ``child`` in ``frame``."""
    msg = Odometry()
    msg.header.frame_id, msg.child_frame_id = frame, child
    return msg


def fill_odometry(
    msg: Odometry,
    stamp: Time,
    pose: Tuple[float, float, float],
    body_velocity: Tuple[float, float, float],
) -> Odometry:
    """``msg`` stamped, in metres: ``pose`` ``(x_mm, y_mm, theta_rad)`` in its frame,
    ``body_velocity`` ``(vx_mm_s, vy_mm_s, omega_rad_s)`` in its child frame."""
    msg.header.stamp = stamp
    p = msg.pose.pose
    p.position.x, p.position.y = pose[0] * MM, pose[1] * MM
    p.orientation.x, p.orientation.y, p.orientation.z, p.orientation.w = mapping.yaw_quaternion(
        pose[2]
    )
    t = msg.twist.twist
    t.linear.x, t.linear.y, t.angular.z = (
        body_velocity[0] * MM,
        body_velocity[1] * MM,
        body_velocity[2],
    )
    return msg


def camera_info_msg(model: Dict[str, Any]) -> CameraInfo:
    """A camera model (``Scenario.camera_model``) as a ``CameraInfo``."""
    return CameraInfo(**dataclasses.asdict(mapping.camera_info(model)))


class Bridge:
    """A simulation of ``scenario`` behind a ROS 2 node named ``omniloop``."""

    def __init__(
        self, scenario: "omniloop.Scenario", options: BridgeOptions, node_name: str = "omniloop"
    ):
        self.scenario, self.options = scenario, options
        self.node = Node(node_name)
        self.executor = SingleThreadedExecutor()
        self.executor.add_node(self.node)
        log = self.node.get_logger()
        seed = scenario.seed if options.seed is None else options.seed
        self.node.declare_parameter("seed", seed)
        # The command line's values are the parameters' defaults: `--ros-args -p NAME:=V` wins.
        stamped: Any = self.node.declare_parameter("twist_stamped", options.twist_stamped).value
        options.twist_stamped = bool(stamped)
        timeout: Any = self.node.declare_parameter("cmd_vel_timeout", options.cmd_vel_timeout_s).value
        options.cmd_vel_timeout_s = float(timeout)
        self.node.add_on_set_parameters_callback(self.on_parameters)
        self.t_s = 0.0
        self.clock = self.node.create_publisher(Clock, "/clock", RELIABLE)
        self.clock_msg = Clock()
        self.tf = None
        if TFMessage is not None:
            self.tf = self.node.create_publisher(TFMessage, "/tf", RELIABLE)
        else:
            log.info(
                "tf2_msgs cannot be imported (it has no wheel on the package index): /tf is not "
                "published; source a ROS 2 installation for it"
            )
        names, team = list(scenario.robots), scenario.is_team
        self.ports: List[RobotPort] = []
        for name in names:
            ns = name if team or name != "robot" else "omniloop"
            self.ports.append(RobotPort(self, name, ns, f"{ns}/" if team else ""))
        # /ground_truth/ball: made with the simulation, where the scenario has a ball.
        self.ball: Optional[Publisher[Odometry]] = None
        self.ball_msg = odometry_frames("map", "ball")
        self.ball_msg.pose.pose.orientation.w = 1.0
        self.sim: Optional[omniloop.Simulation] = None
        self.paused = False
        self.steps_asked = 0
        self.reset_asked = False
        self.written = False
        self.latencies_s: List[float] = []
        self.published_at = self.episode_wall = time.perf_counter()
        self.node.create_service(Trigger, "~/reset", self.on_reset)
        self.node.create_service(SetBool, "~/pause", self.on_pause)
        self.node.create_service(Trigger, "~/step", self.on_step)
        subs = [p.cmd_vel for p in self.ports if p.cmd_vel is not None]
        kicks = [s for p in self.ports for s in p.ball_subs]
        self.kicks = bool(kicks)
        self.commands = (
            CommandWait.of(self.node, subs + kicks) if options.lockstep and subs else None
        )
        mode = "lockstep" if options.lockstep else f"realtime x{options.realtime_factor:g}"
        log.info(
            f"scenario {scenario.name!r}, seed {self.seed()}, {mode}, robots driven by {options.robot}: "
            + ", ".join(f"/{p.ns}" for p in self.ports)
        )

    def on_parameters(self, params: List[Parameter[Any]]) -> SetParametersResult:
        """``cmd_vel_timeout`` takes effect at once, ``seed`` at the next reset;
        ``twist_stamped`` is fixed once the subscription is made."""
        for p in params:
            if p.name == "seed" and not int(p.value) >= 0:
                return SetParametersResult(successful=False, reason="a seed is >= 0")
            if p.name == "cmd_vel_timeout":
                value = float(p.value)
                if not value >= 0:
                    return SetParametersResult(successful=False, reason="must be >= 0 (s)")
                self.options.cmd_vel_timeout_s = value
            if p.name == "twist_stamped" and bool(p.value) != self.options.twist_stamped:
                return SetParametersResult(
                    successful=False, reason="fixed at start: restart with --twist-stamped"
                )
        return SetParametersResult(successful=True)

    # Services: each only asks; the loop acts between cycles.
    def on_reset(self, _request: Any, response: Any) -> Any:
        self.reset_asked = True
        response.success, response.message = True, f"a new episode with seed {self.seed()}"
        return response

    def on_pause(self, request: Any, response: Any) -> Any:
        self.paused = bool(request.data)
        response.success, response.message = True, "paused" if self.paused else "running"
        return response

    def on_step(self, _request: Any, response: Any) -> Any:
        self.steps_asked += int(self.paused)
        response.success = self.paused
        response.message = "one cycle" if self.paused else "running: pause first"
        return response

    def seed(self) -> int:
        return int(self.node.get_parameter("seed").value)

    def publish_tf(self, port: RobotPort, obs: omniloop.Observation, stamp: Time) -> None:
        if self.tf is None:
            return
        x, y, theta = obs.odometry_pose
        tfs = [
            transform(
                stamp,
                port.frame("odom"),
                port.frame("base_link"),
                (x * MM, y * MM, 0.0),
                mapping.yaw_quaternion(theta),
            )
        ]
        for sensor, model in port.models.items():
            pose = model["model_frame_in_body"]
            pan0 = model.get("pan_rad", 0.0)
            rot = mapping.panned(pose["rotation"], obs.actuators.get(sensor, pan0) - pan0)
            t = [v * MM for v in pose["translation_mm"]]
            tfs.append(
                transform(
                    stamp,
                    port.frame("base_link"),
                    port.frame(f"{sensor}_optical"),
                    t,
                    mapping.matrix_quaternion(rot),
                )
            )
        if port.detector is not None:
            ax, ay = port.scan_axis_mm
            tfs.append(
                transform(
                    stamp,
                    port.frame("base_link"),
                    port.frame(f"{port.scan_sensor}_scan"),
                    (ax * MM, ay * MM, 0.0),
                    (0.0, 0.0, 0.0, 1.0),
                )
            )
        self.tf.publish(TFMessage(transforms=tfs))

    def answered(self) -> None:
        """A command answered the last frame: the time since its publication, kept."""
        self.latencies_s.append(time.perf_counter() - self.published_at)

    def publish(self, obs: Any = None) -> None:
        """Every robot's observation (``obs``, else now's), the clock and the truth."""
        self.published_at = time.perf_counter()
        obs = self.running.observe() if obs is None else obs
        truth: Any = self.running.truth()
        team = self.scenario.is_team
        self.t_s = next(iter(obs.values())).t_s if team else obs.t_s
        self.clock_msg.clock = time_msg(self.t_s)
        self.clock.publish(self.clock_msg)
        for port in self.ports:
            o, t = (obs[port.name], truth[port.name]) if team else (obs, truth)
            port.publish(o, t, self.t_s)
            if port.cmd_vel is not None:
                port.awaiting_t_s = self.t_s
        if self.ball is not None:
            self.publish_ball(self.ball, (truth[self.ports[0].name] if team else truth)["ball"])

    def publish_ball(self, pub: Publisher[Odometry], ball: Ball) -> None:
        """The ball's truth (the simulator's side, for scoring): its centre and velocity in
        ``map``, metres, stamped with the cycle."""
        state = mapping.ball_state(ball)
        msg = self.ball_msg
        msg.header.stamp = self.clock_msg.clock
        p, v = msg.pose.pose.position, msg.twist.twist.linear
        p.x, p.y, p.z = state.position
        v.x, v.y, v.z = state.velocity
        pub.publish(msg)

    @property
    def running(self) -> omniloop.Simulation:
        """The simulation, made by the first episode."""
        if self.sim is None:
            raise RuntimeError("no episode yet: start_episode() makes the simulation")
        return self.sim

    def start_episode(self, seed: int) -> None:
        """A new episode with ``seed``, its first observation published."""
        if self.sim is None:
            o = self.options
            # Every camera is rendered to be published, whatever the software reads.
            frames = all(p.sensors for p in self.ports)
            self.sim = omniloop.Simulation(
                self.scenario, seed=seed, renderer=o.renderer, robot=o.robot, frames=frames
            )
            ports = self.sim.ssl_ports()
            if ports is not None:
                self.node.get_logger().info(
                    "serving the SSL simulation protocol: "
                    + ", ".join(f"{k} {v}" for k, v in ports.items())
                )
            truth: Any = self.sim.truth()
            if "ball" in (next(iter(truth.values())) if self.scenario.is_team else truth):
                # Made before the first frame, so that a node started with it sees that frame.
                self.ball = self.node.create_publisher(Odometry, "/ground_truth/ball", RELIABLE)
        else:
            self.sim.reset(seed=seed)
        for port in self.ports:
            port.attach(self.sim)
            port.publish_goal()
        self.written = False
        self.wait_for_peers()
        self.latencies_s = []
        self.episode_wall = time.perf_counter()
        self.publish()

    def wait_for_peers(self) -> None:
        """In lockstep, until every driven robot's ``cmd_vel`` has a publisher and its topics a
        subscriber, so that no frame is published before the robot's software can answer."""
        if not self.options.lockstep:
            return
        log, said = self.node.get_logger(), False
        for port in self.ports:
            if port.cmd_vel is None:
                continue
            while rclpy.ok() and not (
                self.node.count_publishers(port.cmd_vel.topic_name)
                and port.odom.get_subscription_count()
            ):
                if not said:
                    log.info(
                        f"lockstep: waiting for a node on {port.cmd_vel.topic_name} "
                        f"and /{port.ns}/odom"
                    )
                    said = True
                self.executor.spin_once(timeout_sec=0.05)

    def wait_for_commands(self) -> None:
        """Lockstep: until each driven robot answered the last frame, or the timeout."""
        deadline = time.monotonic() + self.options.lockstep_timeout_s
        while rclpy.ok() and not self.reset_asked:
            waiting = [p for p in self.ports if p.awaiting_t_s is not None]
            if not waiting:
                if self.kicks and self.commands is not None:
                    self.commands.take(0.0)  # a kick sent with the answer, just behind it
                return
            left = deadline - time.monotonic()
            if left <= 0:
                names = ", ".join(p.cmd_vel.topic_name for p in waiting if p.cmd_vel)
                self.node.get_logger().warning(
                    f"lockstep: no command on {names} for t = {self.t_s:.3f} s in "
                    f"{self.options.lockstep_timeout_s:g} s: going on without"
                )
                for p in waiting:
                    p.awaiting_t_s = None
                return
            if self.commands is None or not self.commands.take(min(left, 0.02)):
                # No command (or no lean wait): the executor serves the services too.
                self.executor.spin_once(timeout_sec=0.0 if self.commands else min(left, 0.1))

    def step(self) -> None:
        """One control cycle with each robot's command (and the kicker's and dribbler's
        commands come since the last), then its observation published."""
        if self.options.robot in ("builtin", "ssl"):
            obs = self.running.step()
        elif self.scenario.is_team:
            kicks = {p.name: a for p in self.ports if (a := p.take_actuators()) is not None}
            obs = self.running.step(
                {p.name: p.command_now(self.t_s) for p in self.ports}, actuators=kicks or None
            )
        else:
            port = self.ports[0]
            obs = self.running.step(port.command_now(self.t_s), actuators=port.take_actuators())
        self.publish(obs)

    def finish(self) -> None:
        """The run is over: its files written (once)."""
        if self.written:
            return
        self.written = True
        summary = self.running.summary()
        log = self.node.get_logger()
        log.info(
            f"run over at t = {self.t_s:.2f} s: reached goal {summary.get('reached_goal')}, "
            f"contacts {summary.get('wall_contacts')}"
        )
        wall = time.perf_counter() - self.episode_wall
        cycles = self.running.cycle
        line = f"{cycles} cycles in {wall:.2f} s wall ({cycles / max(wall, 1e-9):.1f} cycles/s)"
        if self.latencies_s:
            ms = sorted(1e3 * x for x in self.latencies_s)
            median, p95 = ms[len(ms) // 2], ms[int(0.95 * (len(ms) - 1))]
            line += f"; frame to answering command: median {median:.2f} ms, p95 {p95:.2f} ms"
        log.info(line)
        if self.options.out is not None:
            self.running.write(self.options.out)
            self.node.get_logger().info(f"wrote the run to {self.options.out}")

    def spin(self) -> None:
        """Runs episodes until shut down (or the first ends, with ``exit_at_end``)."""
        self.start_episode(self.seed())
        wall0, sim0 = time.monotonic(), self.t_s
        next_progress = self.options.progress_s
        while rclpy.ok():
            if self.reset_asked:
                self.reset_asked = False
                self.start_episode(self.seed())
                wall0, sim0, next_progress = time.monotonic(), self.t_s, self.options.progress_s
                continue
            if self.running.done:
                self.finish()
                if self.options.exit_at_end:
                    return
                self.executor.spin_once(timeout_sec=0.1)
                continue
            if self.paused and self.steps_asked == 0:
                self.executor.spin_once(timeout_sec=0.05)
                wall0, sim0 = time.monotonic(), self.t_s
                continue
            if self.options.lockstep:
                self.wait_for_commands()
            else:
                self.pace(wall0, sim0)
            if self.reset_asked or (self.paused and self.steps_asked == 0):
                continue  # asked while waiting: nothing more is stepped
            self.steps_asked = max(0, self.steps_asked - 1)
            self.step()
            if self.options.progress_s > 0 and self.t_s >= next_progress - 1e-9:
                self.node.get_logger().info(f"t = {self.t_s:.1f} s, cycle {self.running.cycle}")
                next_progress += self.options.progress_s

    def pace(self, wall0: float, sim0: float) -> None:
        """Handles callbacks until the wall clock catches up with the next cycle's time."""
        factor = self.options.realtime_factor
        if factor <= 0:
            self.executor.spin_once(timeout_sec=0.0)
            return
        due = wall0 + (self.t_s - sim0) / factor
        while True:
            left = due - time.monotonic()
            self.executor.spin_once(timeout_sec=max(0.0, left))
            if left <= 0:
                return

    def close(self, flush_timeout_s: float = 2.0) -> None:
        """Waits (at most ``flush_timeout_s`` in all) until every subscriber has what was
        published, then leaves: a reliable sample lost on its way (a loaded machine's shared
        memory queue full) is sent again on the writer's next heartbeat, which a process
        exiting at once would never send. The run's last cycle reaches its subscribers. Shut
        down already (Ctrl-C), it leaves at once."""
        end = time.monotonic() + flush_timeout_s
        for publisher in self.node.publishers if self.node.context.ok() else []:
            left = max(0.0, end - time.monotonic())
            publisher.wait_for_all_acked(Duration(seconds=left))
        self.executor.remove_node(self.node)
        self.node.destroy_node()


class CommandWait:
    """Lockstep's wait for ``cmd_vel``: rclpy's wait set on the command subscriptions alone, as
    ``rclpy.wait_for_message`` uses it, without the executor's per-wait bookkeeping (a third
    of a millisecond a cycle on this path)."""

    def __init__(self, node: Node, subs: List[Subscription[Any]]) -> None:
        from rclpy.impl.implementation_singleton import rclpy_implementation as _rclpy

        context = node.context.handle
        if context is None:
            raise TypeError("the node's context is shut down")
        self.wait_set = _rclpy.WaitSet(len(subs), 0, 0, 0, 0, 0, context)
        self.subs = subs

    @classmethod
    def of(cls, node: Node, subs: List[Subscription[Any]]) -> Optional["CommandWait"]:
        """The wait, or ``None`` where this rclpy lacks the wait set (the executor serves)."""
        try:
            return cls(node, subs)
        except (AttributeError, TypeError, ImportError):
            return None

    def take(self, timeout_s: float) -> bool:
        """Waits up to ``timeout_s`` for commands and hands each to its callback; whether any
        came."""
        ws = self.wait_set
        ws.clear_entities()
        for sub in self.subs:
            ws.add_subscription(sub.handle)
        ws.wait(int(timeout_s * 1e9))
        ready = ws.get_ready_entities("subscription")
        took = False
        for sub in self.subs:
            if sub.handle.pointer not in ready:
                continue
            while (taken := sub.handle.take_message(sub.msg_type, sub.raw)) is not None:
                # The command subscriptions' callbacks take the message alone.
                cast(Callable[[Any], None], sub.callback)(taken[0])
                took = True
        return took


def transform(
    stamp: Time,
    parent: str,
    child: str,
    t: Sequence[float],
    q: Tuple[float, float, float, float],
) -> Any:
    msg = TransformStamped()
    msg.header.stamp, msg.header.frame_id, msg.child_frame_id = stamp, parent, child
    msg.transform.translation.x, msg.transform.translation.y, msg.transform.translation.z = t
    r = msg.transform.rotation
    r.x, r.y, r.z, r.w = q
    return msg
