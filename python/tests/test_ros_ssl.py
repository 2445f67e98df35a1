"""`omniloop-ros --robot ssl`: a team's AI drives the robots over the SSL simulation protocol
while the ROS 2 node publishes every robot's own camera; and `Simulation(robot="ssl")`, the same
from Python."""

import os
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path

import pytest

import omniloop
from omniloop import ssl

from conftest import SCENARIOS, ros_domain_id

if sys.version_info < (3, 10):
    pytest.skip("ROS 2's wheels are for Python 3.10 and later", allow_module_level=True)

# ROS 2 is part of the tests' environment (`pip install './python[test,ros]'`): no skip.
os.environ["ROS_DOMAIN_ID"] = str(ros_domain_id())
os.environ["ROS_AUTOMATIC_DISCOVERY_RANGE"] = "LOCALHOST"
import rclpy  # noqa: E402
from nav_msgs.msg import Odometry  # noqa: E402
from rclpy.node import Node  # noqa: E402
from sensor_msgs.msg import Image  # noqa: E402


def free_port() -> int:
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


def two_robots(tmp: Path, duration_s: float) -> "tuple[Path, list[int]]":
    """ssl_match.toml with blue1 and yellow1 only, its ports on free loopback ports (control,
    blue, yellow, vision, referee)."""
    text = (SCENARIOS / "ssl_match.toml").read_text()
    head, *robots = text.split("[[robots]]")
    keep = [r for r in robots if 'name = "blue1"' in r or 'name = "yellow1"' in r]
    head = head.replace("duration_s = 600.0", f"duration_s = {duration_s}")
    ports = [free_port() for _ in range(5)]
    network = (
        "\n[ssl.network]\n"
        'bind_address = "127.0.0.1"\n'
        f"control_port = {ports[0]}\nblue_port = {ports[1]}\nyellow_port = {ports[2]}\n"
        f'vision_address = "127.0.0.1:{ports[3]}"\nreferee_address = "127.0.0.1:{ports[4]}"\n'
    )
    head = head.replace("\n[ssl.vision]\n", network + "\n[ssl.vision]\n")
    path = tmp / "ssl_two.toml"
    path.write_text(head + "".join("[[robots]]" + r for r in keep))
    return path, ports


def test_a_simulation_served_over_the_protocol_takes_its_commands_and_gives_frames(tmp_path):
    scenario = omniloop.Scenario.load(two_robots(tmp_path, 5.0)[0])
    sim = omniloop.Simulation(scenario, robot="ssl")
    ports = sim.ssl_ports()
    assert ports is not None and set(ports) == {"control", "blue", "yellow", "vision", "referee"}
    start = sim.truth()["blue1"]["x_mm"]
    # Stepped here, the simulation answers the ports as it steps: send, step, read.
    RobotControl = ssl.message_class("RobotControl")
    Response = ssl.message_class("RobotControlResponse")
    blue = ssl.parse_address(ports["blue"])
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
        s.settimeout(2.0)

        def send(robot_id: int) -> None:
            c = RobotControl()
            c.robot_commands.append(ssl.local_velocity(robot_id, 1.0, 0.0))
            s.sendto(c.SerializeToString(), blue)

        for _ in range(40):
            send(0)
            obs = sim.step()
            answer = Response.FromString(s.recv(65536))
            assert not ssl.error_codes(answer), ssl.error_codes(answer)
            assert [f.id for f in answer.feedback] == [0]
        send(7)
        sim.step()
        assert ssl.error_codes(Response.FromString(s.recv(65536))) == ["UNKNOWN_ROBOT"]
    end = sim.truth()["blue1"]["x_mm"]
    assert end - start > 150.0, (start, end)
    assert obs["blue1"].frames["omni"].shape == (220, 256, 3)
    with pytest.raises(RuntimeError, match="cannot be reset"):
        sim.reset()


class Watcher(Node):
    """Counts blue1's camera frames and keeps its true pose."""

    def __init__(self) -> None:
        super().__init__("omniloop_ssl_watcher")
        self.images = 0
        self.truth: list = []
        self.create_subscription(Image, "/blue1/omni/image_raw", self.on_image, 10)
        self.create_subscription(Odometry, "/blue1/ground_truth/odom", self.truth.append, 10)

    def on_image(self, _msg: Image) -> None:
        self.images += 1


def test_the_ros_node_publishes_the_cameras_of_robots_a_team_ai_drives(tmp_path):
    path, ports = two_robots(tmp_path, 6.0)
    script = Path(sys.executable).parent / "omniloop-ros"
    node = subprocess.Popen(
        [str(script), str(path), "--robot", "ssl", "--exit-at-end", "--out", str(tmp_path / "out")],
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
    )
    rclpy.init()
    watcher = Watcher()
    local = lambda p: f"127.0.0.1:{p}"  # noqa: E731
    try:
        deadline = time.monotonic() + 60
        while not watcher.truth:
            rclpy.spin_once(watcher, timeout_sec=0.05)
            assert node.poll() is None, node.stdout.read() if node.stdout else ""
            assert time.monotonic() < deadline, "no ground truth from the node"
        x0 = watcher.truth[-1].pose.pose.position.x
        with ssl.SslClient(
            local(ports[0]),
            local(ports[1]),
            local(ports[2]),
            timeout_s=2.0,
        ) as client:
            until = time.monotonic() + 1.5
            while time.monotonic() < until:
                client.command("blue", [ssl.local_velocity(0, 1.0, 0.0)])
                rclpy.spin_once(watcher, timeout_sec=0.02)
        for _ in range(20):
            rclpy.spin_once(watcher, timeout_sec=0.05)
        x1 = watcher.truth[-1].pose.pose.position.x
        rc = node.wait(timeout=60)
    finally:
        if node.poll() is None:
            node.send_signal(signal.SIGINT)
            node.wait(timeout=10)
        watcher.destroy_node()
        rclpy.try_shutdown()
    log = node.stdout.read() if node.stdout else ""
    assert rc == 0, log
    assert "serving the SSL simulation protocol" in log, log
    assert x1 - x0 > 0.3, (x0, x1, log)
    assert watcher.images >= 20, (watcher.images, log)
    assert (tmp_path / "out" / "trajectory.csv").exists()
