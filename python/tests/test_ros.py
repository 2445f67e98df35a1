"""`omniloop-ros --lockstep` as a separate process, driven to its goal through DDS by an rclpy
node that sees only `odom`; what it publishes checked against `omniloop.Simulation` run here
with the same seed and commands."""

import json
import math
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

import omniloop
from omniloop.ros import mapping

from conftest import ROOT, SCENARIOS, ros_domain_id

if sys.version_info < (3, 10):
    pytest.skip("ROS 2's wheels are for Python 3.10 and later", allow_module_level=True)

# ROS 2 is part of the tests' environment (`pip install './python[test,ros]'`): no skip.
os.environ["ROS_DOMAIN_ID"] = str(ros_domain_id())
os.environ["ROS_AUTOMATIC_DISCOVERY_RANGE"] = "LOCALHOST"
import rclpy  # noqa: E402
from geometry_msgs.msg import PoseStamped, Twist, TwistStamped, Vector3  # noqa: E402
from nav_msgs.msg import Odometry  # noqa: E402
from rclpy.node import Node  # noqa: E402
from rclpy.qos import DurabilityPolicy, QoSProfile  # noqa: E402
from rosgraph_msgs.msg import Clock  # noqa: E402
from sensor_msgs.msg import CameraInfo, Image, LaserScan  # noqa: E402
from std_msgs.msg import Bool, Float32  # noqa: E402
from std_srvs.srv import SetBool, Trigger  # noqa: E402

SCENARIO = SCENARIOS / "ros_smoke.toml"
NS = "/omniloop"
NAN_AT, RESET_AT = 5, 12  # cycles of the first episode


KEYS = {
    "image": (Image, "omni/image_raw"),
    "info": (CameraInfo, "omni/camera_info"),
    "scan": (LaserScan, "scan"),
    "truth": (Odometry, "ground_truth/odom"),
}


class Client(Node):
    """Drives to the goal from odom alone, one command per cycle; records what it gets.

    A cycle is answered once all its messages are here (each topic's and its ``/clock``), as a
    node synchronising its inputs would: a sample lost on a loaded machine is sent again on the
    writer's next heartbeat, and lockstep waits for it instead of publishing past it."""

    def __init__(self) -> None:
        super().__init__("omniloop_test_client")
        self.msgs = {key: [] for key in [*KEYS, "odom"]}
        self.commands = []  # the command answering each odom (None: a reset answered it)
        self.goal = None
        self.clock = []
        latched = QoSProfile(depth=1, durability=DurabilityPolicy.TRANSIENT_LOCAL)
        self.create_subscription(PoseStamped, f"{NS}/goal_pose", self.on_goal, latched)
        for key, (kind, topic) in KEYS.items():
            self.create_subscription(kind, f"{NS}/{topic}", self.recorder(key), 10)
        self.create_subscription(Odometry, f"{NS}/odom", self.recorder("odom"), 10)
        self.create_subscription(Clock, "/clock", self.on_clock, 100)
        self.cmd = self.create_publisher(Twist, f"{NS}/cmd_vel", 10)
        self.reset = self.create_client(Trigger, "/omniloop/reset")
        self.last = time.monotonic()

    def recorder(self, key: str):
        def record(msg) -> None:
            self.msgs[key].append(msg)
            if key == "odom":
                self.last = time.monotonic()
            self.answer_when_complete()

        return record

    def on_goal(self, msg: PoseStamped) -> None:
        self.goal = (msg.pose.position.x, msg.pose.position.y)
        self.answer_when_complete()

    def on_clock(self, msg: Clock) -> None:
        self.clock.append(msg.clock)
        self.answer_when_complete()

    def answer_when_complete(self) -> None:
        """Answers each odom in turn once the goal, its cycle's other topics and its clock are
        here."""
        odoms = self.msgs["odom"]
        while self.goal is not None and len(self.commands) < len(odoms):
            cycle = len(self.commands)
            if any(len(msgs) <= cycle for msgs in self.msgs.values()):
                return
            if all(c != odoms[cycle].header.stamp for c in self.clock):
                return
            self.answer(cycle, odoms[cycle])

    def answer(self, cycle: int, msg: Odometry) -> None:
        if cycle == RESET_AT:
            self.reset.call_async(Trigger.Request())
            self.commands.append(None)  # the reset answers this frame
            return
        if cycle == NAN_AT:
            bad = Twist()
            bad.linear.x = float("nan")
            self.cmd.publish(bad)  # refused: the node goes on waiting for a good one
        p, q = msg.pose.pose.position, msg.pose.pose.orientation
        theta = 2.0 * math.atan2(q.z, q.w)
        dx, dy = self.goal[0] - p.x, self.goal[1] - p.y
        dist = math.hypot(dx, dy)
        speed = min(0.8, 2.0 * dist) / max(dist, 1e-9)
        c, s = math.cos(theta), math.sin(theta)
        cmd = Twist()
        cmd.linear.x, cmd.linear.y = speed * (c * dx + s * dy), speed * (c * dy - s * dx)
        self.commands.append(cmd)
        self.cmd.publish(cmd)

    def episodes(self):
        """Per episode, per cycle: each topic's message and the command that answered it."""
        split = {key: episodes_of(msgs) for key, msgs in self.msgs.items()}
        out, k = [], 0
        counts = {key: [len(e) for e in episodes] for key, episodes in split.items()}
        assert all(c == counts["odom"] for c in counts.values()), f"messages an episode: {counts}"
        for e, odoms in enumerate(split["odom"]):
            cycles = []
            for c in range(len(odoms)):
                record = {key: split[key][e][c] for key in split}
                record["command"] = self.commands[k]
                k += 1
                cycles.append(record)
            out.append(cycles)
        return out


def episodes_of(msgs):
    """Messages split where the stamp goes back to 0 (a reset)."""
    out = [[]]
    for m in msgs:
        if stamp_s(m) == 0.0 and out[-1]:
            out.append([])
        out[-1].append(m)
    return out


def bridge_command(out: Path) -> list:
    script = Path(sys.executable).parent / "omniloop-ros"
    return [str(script), str(SCENARIO), "--lockstep", "--exit-at-end", "--out", str(out)]


def drive(out: Path):
    """One lockstep run of the bridge and the client; the client and the node's exit code."""
    node = subprocess.Popen(
        bridge_command(out), stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True
    )
    client = Client()
    try:
        while client.goal is None or not client.cmd.get_subscription_count():
            rclpy.spin_once(client, timeout_sec=0.05)
            assert node.poll() is None, node.stdout.read()
            assert time.monotonic() - client.last < 60, "no bridge came up"
        deadline = time.monotonic() + 300
        while node.poll() is None:  # the node exits at the run's end
            rclpy.spin_once(client, timeout_sec=0.05)
            assert time.monotonic() < deadline, "the run did not end in 5 minutes"
        end = time.monotonic() + 1.0
        while time.monotonic() < end:  # what reached the client before the node left
            rclpy.spin_once(client, timeout_sec=0.05)
        rc = node.wait(timeout=30)
    finally:
        if node.poll() is None:
            node.send_signal(signal.SIGINT)
            node.wait(timeout=10)
        client.destroy_node()
    return client, rc, node.stdout.read(), out


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    rclpy.init()
    try:
        a = drive(tmp_path_factory.mktemp("ros_a"))
        b = drive(tmp_path_factory.mktemp("ros_b"))
    finally:
        rclpy.shutdown()
    return a, b


def replay(episodes):
    """The same episodes run here: each cycle's observation and truth, and the detector."""
    scenario = omniloop.Scenario.load(SCENARIO)
    sim = omniloop.Simulation(scenario, frames=True)
    robot = scenario.robot
    detector = sim.free_space_detector()
    out = []
    for episode in episodes:
        obs, steps = sim.reset(), []
        detector = sim.free_space_detector()
        for record in episode:
            steps.append((obs, sim.truth(), detector.detect(obs.frames["omni"])))
            cmd = record["command"]
            if cmd is not None and not obs.done:
                obs = sim.step(
                    mapping.body_command(cmd.linear.x, cmd.linear.y, cmd.angular.z, robot)
                )
        out.append(steps)
    return out, sim


def stamp_s(msg) -> float:
    return mapping.seconds(msg.header.stamp.sec, msg.header.stamp.nanosec)


def test_the_robot_reaches_its_goal_through_ros_and_the_node_survives_a_nan(runs):
    (client, rc, log, _), _ = runs
    assert rc == 0, log
    episodes = client.episodes()
    assert len(episodes) == 2, "the reset began a second episode"
    assert len(episodes[0]) == RESET_AT + 1
    assert "not finite" in log and "refused" in log  # the NaN, logged; the run went on
    truth = episodes[1][-1]["truth"].pose.pose.position
    goal = client.goal
    assert math.hypot(truth.x - goal[0], truth.y - goal[1]) < 0.1
    assert "reached goal True" in log


def test_what_the_node_publishes_is_the_simulations_own(runs):
    (client, _, _, _), _ = runs
    episodes = client.episodes()
    expected, _ = replay(episodes)
    clock = {mapping.seconds(c.sec, c.nanosec) for c in client.clock}
    n = 0
    for episode, steps in zip(episodes, expected):
        assert len(episode) == len(steps)
        for record, (obs, truth, free) in zip(episode, steps):
            img, info, scan, odom, true = (
                record[k] for k in ("image", "info", "scan", "odom", "truth")
            )
            # Types, encodings, frames.
            assert isinstance(img, Image) and img.encoding == "rgb8" and img.step == 3 * img.width
            assert (img.height, img.width) == obs.frames["omni"].shape[:2]
            assert img.header.frame_id == info.header.frame_id == "omni_optical"
            assert info.distortion_model == "omnidir_mei" and len(info.d) == 5
            assert (odom.header.frame_id, odom.child_frame_id) == ("odom", "base_link")
            assert true.header.frame_id == "map" and scan.header.frame_id == "omni_scan"
            # Stamps on simulation time, /clock beside them.
            t = obs.t_s
            for m in (img, info, scan, odom, true):
                assert abs(stamp_s(m) - t) < 1e-9
            assert any(abs(c - t) < 1e-9 for c in clock)
            # The image's bytes are the frame's.
            assert bytes(img.data) == obs.frames["omni"].tobytes()
            # Odometry and truth in metres.
            x, y, theta = obs.odometry_pose
            assert odom.pose.pose.position.x == pytest.approx(x / 1000, abs=1e-12)
            assert odom.pose.pose.position.y == pytest.approx(y / 1000, abs=1e-12)
            assert 2 * math.atan2(
                odom.pose.pose.orientation.z, odom.pose.pose.orientation.w
            ) == pytest.approx(theta, abs=1e-9)
            assert odom.twist.twist.linear.x == pytest.approx(
                obs.odometry.vx_mm_s / 1000, abs=1e-12
            )
            assert true.pose.pose.position.x == pytest.approx(truth["x_mm"] / 1000, abs=1e-12)
            # The scan: the free-space stage's distances, metres, +inf where free throughout.
            ranges = np.array(scan.ranges, dtype=float)
            free_through = free["free_mm"] >= free["range_mm"]
            assert np.all(np.isinf(ranges[free_through]))
            assert np.allclose(
                ranges[~free_through], free["free_mm"][~free_through] / 1000, rtol=1e-6
            )
            assert scan.range_max == pytest.approx(free["range_mm"] / 1000)
            n += 1
    assert n > 50
    # The covariance is the odometry's: it grew over the first episode.
    assert episodes[1][-1]["odom"].pose.covariance[0] > 0.0


def test_reset_gives_the_same_first_frame_again(runs):
    (client, _, _, _), _ = runs
    episodes = client.episodes()
    first, again = episodes[0][0]["image"], episodes[1][0]["image"]
    assert stamp_s(again) == 0.0
    assert bytes(first.data) == bytes(again.data)
    assert bytes(episodes[0][3]["image"].data) != bytes(first.data)


def test_two_lockstep_runs_give_the_same_trajectory_bit_for_bit(runs):
    (_, _, _, a), (_, rc, log, b) = runs
    assert rc == 0, log
    ta, tb = ((d / "trajectory.csv").read_bytes() for d in (a, b))
    assert len(ta.splitlines()) > 50 and ta == tb


def test_the_docs_node_is_the_example_and_drives_to_the_goal(tmp_path):
    """docs/ros.md's node is python/examples/ros_drive_to_goal.py (less its docstring), and it
    brings the robot to its goal through a lockstep bridge."""
    example = (ROOT / "python/examples/ros_drive_to_goal.py").read_text()
    body = example[example.index('"""', 3) + 4 :].lstrip("\n")
    docs = (ROOT / "docs/ros.md").read_text()
    block = docs[docs.index("## A node that drives to the goal") :]
    assert (
        block[block.index("```python\n") + 10 : block.index("```", block.index("```python\n") + 10)]
        == body
    )
    node = subprocess.Popen(
        bridge_command(tmp_path), stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True
    )
    try:
        drive = subprocess.run(
            [sys.executable, str(ROOT / "python/examples/ros_drive_to_goal.py")],
            capture_output=True,
            text=True,
            timeout=120,
        )
        log = node.communicate(timeout=60)[0]
    finally:
        if node.poll() is None:
            node.kill()
    assert drive.returncode == 0, drive.stderr
    assert node.returncode == 0 and "reached goal True" in log, log


def test_a_team_publishes_a_namespace_per_robot():
    """Two robots of a corridor, driven by the built-in software: each its odom, scan and
    image under its own name, in frames prefixed with it."""
    path = SCENARIOS / "corridor_passing.toml"
    names = list(omniloop.Scenario.load(path).robots)
    script = Path(sys.executable).parent / "omniloop-ros"
    cmd = [str(script), str(path), "--robot", "builtin", "--realtime", "0", "--exit-at-end"]
    got = {(n, k): [] for n in names for k in ("odom", "scan", "image")}
    rclpy.init()
    try:
        client = rclpy.create_node("omniloop_team_client")
        for n in names:
            client.create_subscription(Odometry, f"/{n}/odom", got[(n, "odom")].append, 10)
            client.create_subscription(LaserScan, f"/{n}/scan", got[(n, "scan")].append, 10)
            client.create_subscription(Image, f"/{n}/omni/image_raw", got[(n, "image")].append, 10)
        node = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
        try:
            while node.poll() is None:
                rclpy.spin_once(client, timeout_sec=0.05)
            for _ in range(20):
                rclpy.spin_once(client, timeout_sec=0.01)
        finally:
            if node.poll() is None:
                node.kill()
        client.destroy_node()
    finally:
        rclpy.shutdown()
    log = node.stdout.read()
    assert node.returncode == 0, log
    assert len(names) == 2
    for n in names:
        odom, scan, image = (got[(n, k)] for k in ("odom", "scan", "image"))
        assert len(odom) > 10 and len(scan) > 10 and len(image) > 10, log
        assert (odom[-1].header.frame_id, odom[-1].child_frame_id) == (
            f"{n}/odom",
            f"{n}/base_link",
        )
        assert scan[-1].header.frame_id == f"{n}/omni_scan"
        assert image[-1].header.frame_id == f"{n}/omni_optical"
    # Each its own robot: the two odometries are far apart.
    a, b = (got[(n, "odom")][-1].pose.pose.position for n in names)
    assert math.hypot(a.x - b.x, a.y - b.y) > 0.3


def test_pause_step_and_reset_by_hand():
    """Paused, the simulation stands; each `~/step` is one cycle; `~/reset` starts again."""
    script = Path(sys.executable).parent / "omniloop-ros"
    cmd = [str(script), str(SCENARIO), "--robot", "builtin", "--realtime", "1"]
    odoms = []
    rclpy.init()
    node = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    try:
        client = rclpy.create_node("omniloop_hand_client")
        client.create_subscription(Odometry, f"{NS}/odom", odoms.append, 50)
        pause = client.create_client(SetBool, "/omniloop/pause")
        step = client.create_client(Trigger, "/omniloop/step")
        reset = client.create_client(Trigger, "/omniloop/reset")

        def call(service, request):
            assert service.wait_for_service(timeout_sec=60)
            future = service.call_async(request)
            rclpy.spin_until_future_complete(client, future, timeout_sec=10)
            return future.result()

        def spin_for(seconds):
            end = time.monotonic() + seconds
            while time.monotonic() < end:
                rclpy.spin_once(client, timeout_sec=0.02)

        while len(odoms) < 5:
            spin_for(0.05)
            assert node.poll() is None
        assert call(pause, SetBool.Request(data=True)).success
        spin_for(0.3)  # what was on its way
        held = len(odoms)
        spin_for(0.5)
        assert len(odoms) == held, "paused, yet it stepped"
        for _ in range(3):
            assert call(step, Trigger.Request()).success
        spin_for(0.3)
        assert len(odoms) == held + 3
        dt = [stamp_s(b) - stamp_s(a) for a, b in zip(odoms[held - 1 :], odoms[held:])]
        assert dt == pytest.approx([0.04] * 3)
        assert call(reset, Trigger.Request()).success
        spin_for(0.5)
        assert stamp_s(odoms[held + 3]) == 0.0
        client.destroy_node()
    finally:
        node.send_signal(signal.SIGINT)
        log = node.communicate(timeout=20)[0]
        rclpy.shutdown()
    assert node.returncode == 0, log


def test_twist_stamped_commands_drive_in_lockstep():
    """With `--twist-stamped`, a command answers the frame its stamp is at or after; the
    robot reaches its goal on such commands alone."""
    script = Path(sys.executable).parent / "omniloop-ros"
    cmd = [str(script), str(SCENARIO), "--lockstep", "--twist-stamped", "--exit-at-end"]
    goal = []
    rclpy.init()
    node = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    try:
        client = rclpy.create_node("omniloop_stamped_client")
        pub = client.create_publisher(TwistStamped, f"{NS}/cmd_vel", 10)
        latched = QoSProfile(depth=1, durability=DurabilityPolicy.TRANSIENT_LOCAL)
        client.create_subscription(
            PoseStamped, f"{NS}/goal_pose", lambda m: goal.append(m.pose.position), latched
        )

        def answer(msg: Odometry) -> None:
            p, g = msg.pose.pose.position, goal[0] if goal else msg.pose.pose.position
            dx, dy = g.x - p.x, g.y - p.y  # heading stays 0: body = map axes
            k = min(0.8, 2.0 * math.hypot(dx, dy)) / max(math.hypot(dx, dy), 1e-9)
            out = TwistStamped()
            out.header.stamp = msg.header.stamp
            out.twist.linear.x, out.twist.linear.y = k * dx, k * dy
            pub.publish(out)

        client.create_subscription(Odometry, f"{NS}/odom", answer, 10)
        while node.poll() is None:
            rclpy.spin_once(client, timeout_sec=0.05)
        client.destroy_node()
    finally:
        if node.poll() is None:
            node.kill()
        rclpy.shutdown()
    log = node.stdout.read()
    assert node.returncode == 0 and "reached goal True" in log, log
    assert "no command" not in log  # every cycle was answered in time


def test_a_robot_without_a_camera_publishes_its_odometry(tmp_path):
    """smoke.toml has no camera: no image, no scan, the run goes through and is written."""
    script = Path(sys.executable).parent / "omniloop-ros"
    cmd = [str(script), str(SCENARIOS / "smoke.toml"), "--robot", "builtin", "--realtime", "0"]
    r = subprocess.run(
        [*cmd, "--exit-at-end", "--out", str(tmp_path)], capture_output=True, text=True, timeout=120
    )
    assert r.returncode == 0, r.stderr
    assert "no scan" in r.stderr and "run over at t = " in r.stderr
    assert (tmp_path / "trajectory.csv").read_text().count("\n") > 100


class Kicker(Node):
    """Plays ball_rollout.toml's robot in lockstep, one answer an odom: bad kicker and dribbler
    commands first, then the dribbler on while backing off, then a 3 m/s kick standing."""

    # Backing off for a second at 0.3 m/s (300 mm/s^2: a second to speed, a second to stop).
    BAD, DRIBBLE, BACK, KICK = 1, 2, range(3, 28), 60

    def __init__(self) -> None:
        super().__init__("omniloop_kick_client")
        self.odoms, self.barrier, self.balls = [], [], []
        self.create_subscription(Odometry, f"{NS}/odom", self.on_odom, 10)
        self.create_subscription(Bool, f"{NS}/ball_in_dribbler", self.barrier.append, 10)
        self.create_subscription(Odometry, "/ground_truth/ball", self.balls.append, 10)
        self.cmd = self.create_publisher(Twist, f"{NS}/cmd_vel", 10)
        self.kick = self.create_publisher(Vector3, f"{NS}/kick", 10)
        self.dribbler = self.create_publisher(Float32, f"{NS}/dribbler", 10)
        self.last = time.monotonic()

    def on_odom(self, msg: Odometry) -> None:
        self.last = time.monotonic()
        self.odoms.append(msg)
        cycle, cmd = len(self.odoms) - 1, Twist()
        # The kicker's commands go before the cmd_vel that answers the frame.
        if cycle == self.BAD:
            self.kick.publish(Vector3(x=7.0))  # over the rules' 6.5 m/s
            self.dribbler.publish(Float32(data=float("nan")))
        if cycle == self.BAD + 1:
            self.kick.publish(Vector3(x=-1.0))  # refused too (the warning held back: throttled)
        if cycle == self.DRIBBLE:
            self.dribbler.publish(Float32(data=3000.0))
        if cycle in self.BACK:
            cmd.linear.x = -0.3
        if cycle == self.KICK:
            self.kick.publish(Vector3(x=3.0))
        self.cmd.publish(cmd)


def test_a_kicker_dribbles_and_kicks_through_ros_and_bad_commands_are_refused(tmp_path):
    """ball_rollout.toml: the ball lies at the robot's dribbler. A kick over the limit and a
    NaN dribbler speed are refused with a warning and the node goes on; with the dribbler on,
    the robot backs off drawing the ball with it (the light barrier on throughout); a 3 m/s kick
    sends it off: the barrier goes off and /ground_truth/ball has it rolling away at ~3 m/s."""
    script = Path(sys.executable).parent / "omniloop-ros"
    scenario = SCENARIOS / "ball_rollout.toml"
    cmd = [str(script), str(scenario), "--lockstep", "--exit-at-end", "--out", str(tmp_path)]
    rclpy.init()
    node = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    try:
        client = Kicker()
        while node.poll() is None and time.monotonic() - client.last < 60:
            rclpy.spin_once(client, timeout_sec=0.05)
        for _ in range(20):
            rclpy.spin_once(client, timeout_sec=0.01)
        client.destroy_node()
    finally:
        if node.poll() is None:
            node.kill()
        rclpy.shutdown()
    log = node.stdout.read()
    assert node.returncode == 0, log
    assert "over the kicker's limit of 6.5 m/s: refused" in log, log
    assert "dribbler speed nan rpm" in log and "refused" in log, log
    n = len(client.odoms)
    assert n == 376 and len(client.barrier) == n and len(client.balls) == n, log
    barrier = [m.data for m in client.barrier]
    balls = [(stamp_s(m), m.pose.pose.position, m.twist.twist.linear) for m in client.balls]
    assert balls[0][0] == 0.0 and balls[-1][0] == pytest.approx(15.0)
    assert all(m.header.frame_id == "map" and m.child_frame_id == "ball" for m in client.balls)
    # The first frame after the kick fired: the kick's own cycle (sent before the cmd_vel
    # that answered it, it arrives first on one machine), or the next should DDS reorder them.
    kick = barrier.index(False)
    assert kick in (Kicker.KICK + 1, Kicker.KICK + 2)
    # Held until the kick: the refused kicks did not fire; backing off drew the ball back.
    assert balls[Kicker.KICK][1].x < balls[0][1].x - 0.2
    assert all(abs(v.x) < 0.35 for _, _, v in balls[:kick])
    # The kick: off the dribbler at 3 m/s less a cycle's sliding, rolling away along +x.
    assert not any(barrier[kick:])
    assert balls[kick][2].x == pytest.approx(3.0 - 3.9 * 0.04, abs=0.05)
    assert balls[-1][1].x > balls[kick][1].x + 2.0
    events = [json.loads(line) for line in (tmp_path / "events.jsonl").read_text().splitlines()]
    kicks = [e for e in events if e["event"] == "kick"]
    assert len(kicks) == 1 and kicks[0]["speed_mm_s"] == pytest.approx(3000.0)
