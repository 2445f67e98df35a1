"""`omniloop ssl` from the outside, as a Small-Size team's software meets it: the simulation
protocol's ports driven with `omniloop.ssl`'s client, vision and the referee received, bad
datagrams answered, the lockstep mode's repeatability, a third-party vision client
(pySSLVision, in its own virtual environment) reading the realistic vision, and the scripted
match of python/examples/ssl_match.py.

The binary is $OMNILOOP_BIN (scripts/test.sh sets it after `cargo test`), else
target/debug/omniloop; pySSLVision's environment is $OMNILOOP_SSLVISION_VENV, else
.venv-sslvision (scripts/test.sh makes it). Either missing fails the tests, naming what to do.
"""

import json
import math
import os
import subprocess
import sys
import time
from pathlib import Path

import pytest

from conftest import ROOT

from omniloop import ssl

SCENARIO = ROOT / "scenarios" / "ssl_match.toml"
SSLVISION_VENV = ROOT / os.environ.get("OMNILOOP_SSLVISION_VENV", ".venv-sslvision")
# The scenario's wheels, degrees clockwise from forward: front right, back right, back left,
# front left ([ssl] wheel_angles_deg).
WHEEL_ANGLES_DEG = (60.0, 135.0, 225.0, 300.0)


@pytest.fixture(scope="module")
def binary() -> str:
    path = os.environ.get("OMNILOOP_BIN") or str(ROOT / "target" / "debug" / "omniloop")
    if not (Path(path).is_file() and os.access(path, os.X_OK)):
        pytest.fail(
            f"no omniloop binary at {path}: run `cargo build` (or scripts/test.sh), or set "
            "OMNILOOP_BIN"
        )
    return path


@pytest.fixture(scope="module")
def sslvision_python() -> str:
    python = SSLVISION_VENV / "bin" / "python"
    if not python.is_file():
        pytest.fail(
            f"no {python}: scripts/test.sh makes it, or `python3 -m venv .venv-sslvision && "
            ".venv-sslvision/bin/pip install pysslvision==2.0.0 protobuf==3.20.3`"
        )
    return str(python)


@pytest.fixture
def receivers():
    vision, referee = ssl.VisionReceiver(), ssl.RefereeReceiver()
    yield vision, referee
    vision.close()
    referee.close()


def wheel_speeds(forward: float) -> tuple:
    """Rim speeds that drive a robot straight ahead at `forward` m/s (wheel k rolls along
    the tangent at its position, -angle_k from forward)."""
    return tuple(forward * math.sin(math.radians(a)) for a in WHEEL_ANGLES_DEG)


def settle(vision: ssl.VisionReceiver, wall_s: float) -> None:
    """Reads vision for `wall_s` seconds."""
    end = time.monotonic() + wall_s
    while time.monotonic() < end:
        vision.receive(0.02)


# Where each robot starts the drive, what it is told and the direction it must move
# (unit vector in the field's frame). Blue on the -x half, yellow on the +x half, clear of
# each other's paths.
DRIVES = {
    ("blue", 0): ((-3.5, 2.2, 0.0), "local", (0.5, 0.0, 0.0), (1.0, 0.0)),
    ("blue", 1): ((-3.5, 1.2, math.pi / 2), "local", (0.0, -0.5, 0.0), (1.0, 0.0)),
    ("blue", 2): ((-2.5, -1.0, 0.3), "global", (0.0, 0.5, 0.0), (0.0, 1.0)),
    ("blue", 3): ((-1.5, -1.0, -2.0), "global", (-0.5, 0.0, 0.0), (-1.0, 0.0)),
    ("blue", 4): ((-2.5, -2.5, math.pi / 2), "wheels", 0.5, (0.0, 1.0)),
    ("blue", 5): ((-1.0, 2.5, math.pi), "wheels", 0.5, (-1.0, 0.0)),
    ("yellow", 0): ((3.5, 2.2, math.pi), "local", (0.5, 0.0, 0.0), (-1.0, 0.0)),
    ("yellow", 1): ((3.5, 1.2, math.pi), "local", (0.0, 0.5, 0.0), (0.0, -1.0)),
    ("yellow", 2): ((2.5, -1.0, 0.0), "global", (0.0, -0.5, 0.0), (0.0, -1.0)),
    ("yellow", 3): ((1.5, -0.5, 1.0), "global", (0.5, 0.0, 0.0), (1.0, 0.0)),
    ("yellow", 4): ((2.5, -2.2, -math.pi / 2), "wheels", 0.5, (0.0, -1.0)),
    ("yellow", 5): ((1.0, 2.5, 0.0), "wheels", -0.5, (-1.0, 0.0)),
}


def drive_command(robot_id: int, kind: str, value) -> object:
    if kind == "local":
        return ssl.local_velocity(robot_id, *value)
    if kind == "global":
        return ssl.global_velocity(robot_id, *value)
    return ssl.wheel_velocity(robot_id, *wheel_speeds(value))


def test_twelve_robots_drive_and_one_kicks(binary, receivers):
    vision, referee = receivers
    with ssl.serve(
        SCENARIO,
        extra_args=["--no-cameras"],
        binary=binary,
        vision=vision.address,
        referee=referee.address,
    ) as served, served.client() as client:
        # Everyone to a known place, the ball out of the way.
        places = [(t, i, *DRIVES[(t, i)][0], True) for (t, i) in DRIVES]
        assert ssl.error_codes(client.teleport_robots(places)) == []
        assert ssl.error_codes(client.teleport_ball(0.0, -2.8)) == []
        settle(vision, 0.15)
        start = {}
        for (team, i), ((x, y, _), *_rest) in DRIVES.items():
            seen = vision.state.robot(team, i)
            assert seen is not None, f"vision does not see {team} {i}"
            assert math.hypot(seen.x_mm - 1000 * x, seen.y_mm - 1000 * y) < 1.0, (team, i, seen)
            start[(team, i)] = (seen.x_mm, seen.y_mm)
        assert vision.state.ball is not None
        assert math.hypot(vision.state.ball[0], vision.state.ball[1] + 2800) < 1.0

        # One second of commands, every 20 ms (the scenario stops a robot 0.1 s after its
        # last command).
        end = time.monotonic() + 1.0
        answers = 0
        while time.monotonic() < end:
            for team in ("blue", "yellow"):
                commands = [
                    drive_command(i, kind, value)
                    for (t, i), (_, kind, value, _) in DRIVES.items()
                    if t == team
                ]
                r = client.command(team, commands)
                assert ssl.error_codes(r) == [], [e.message for e in r.errors]
                assert sorted(f.id for f in r.feedback) == list(range(6))
                assert all(f.HasField("dribbler_ball_contact") for f in r.feedback)
                answers += 1
            settle(vision, 0.02)
        assert answers > 20
        settle(vision, 0.4)  # they stop after the timeout
        for (team, i), (_, kind, _, (ux, uy)) in DRIVES.items():
            now = vision.state.robot(team, i)
            dx, dy = now.x_mm - start[(team, i)][0], now.y_mm - start[(team, i)][1]
            along, across = dx * ux + dy * uy, -dx * uy + dy * ux
            assert 250 < along < 700 and abs(across) < 100, (team, i, kind, along, across)

        # The kick: blue 0 and the ball 105 mm ahead of it, on a clear line to +x.
        assert ssl.error_codes(client.teleport_robot("blue", 0, -1.0, 0.0, 0.0)) == []
        assert ssl.error_codes(client.teleport_ball(-1.0 + 0.105, 0.0)) == []
        settle(vision, 0.1)
        contact = False
        deadline = time.monotonic() + 2.0
        while not contact and time.monotonic() < deadline:
            r = client.command("blue", [ssl.local_velocity(0, 0.2, 0.0, dribbler_speed=3000)])
            contact = any(f.id == 0 and f.dribbler_ball_contact for f in r.feedback)
            settle(vision, 0.01)
        assert contact, "the light barrier never saw the ball"
        track = []
        end = time.monotonic() + 0.6
        while time.monotonic() < end:
            r = client.command("blue", [ssl.local_velocity(0, 0.2, 0.0, kick_speed=4.0)])
            assert ssl.error_codes(r) == []
            settle(vision, 0.01)
            track.append((vision.state.ball_t, *vision.state.ball))
        client.command("blue", [ssl.local_velocity(0, 0.0, 0.0, kick_speed=0.0)])
        speeds = [
            (b[1] - a[1]) / (b[0] - a[0]) / 1000.0
            for a, b in zip(track, track[1:])
            if b[0] - a[0] > 0.02
        ]
        assert max(speeds) > 1.0, track
        assert track[-1][1] - track[0][1] > 500, track  # it went toward +x

        # Vision's packets stay small enough for clients reading 1024 bytes at a time.
        assert 0 < vision.largest_detection < 1024, vision.largest_detection
        assert vision.malformed == 0
        packet = referee.poll()
        assert packet is not None and packet.command == ssl.Command.FORCE_START
        assert (packet.blue.name, packet.yellow.name) == ("blue", "yellow")
        # A game controller's command sent to the control port goes out at once.
        assert ssl.error_codes(client.referee_command(ssl.Command.STOP)) == []
        deadline = time.monotonic() + 1.0
        while referee.latest.command != ssl.Command.STOP and time.monotonic() < deadline:
            referee.receive(0.1)
        assert referee.latest.command == ssl.Command.STOP
        assert referee.latest.command_counter > packet.command_counter


def test_bad_datagrams_are_answered_and_the_server_goes_on(binary, receivers):
    vision, referee = receivers
    with ssl.serve(
        SCENARIO,
        extra_args=["--no-cameras"],
        binary=binary,
        vision=vision.address,
        referee=referee.address,
    ) as served, served.client() as client:
        good = ssl.RobotControl()
        good.robot_commands.extend([ssl.local_velocity(i, 0.1, 0.0) for i in range(3)])
        garbage = [b"\xff\xff\xff\xff\xff", b"\x0a\x50garbage", good.SerializeToString()[:-3]]
        for payload in garbage:
            for port in ("blue", "yellow"):
                r = ssl.RobotControlResponse.FromString(client.request(port, payload))
                assert ssl.error_codes(r) == ["MALFORMED"], (port, payload)
            r = ssl.SimulatorResponse.FromString(client.request("control", payload))
            assert ssl.error_codes(r) == ["MALFORMED"], payload

        codes = ssl.error_codes
        assert codes(client.command("blue", [ssl.local_velocity(17, 0.5, 0.0)])) == [
            "UNKNOWN_ROBOT"
        ]
        assert codes(client.teleport_robot("yellow", 42, 0.0, 0.0, 0.0)) == ["UNKNOWN_ROBOT"]
        assert codes(client.command("yellow", [ssl.local_velocity(2, math.nan, 0.0)])) == [
            "INVALID_VELOCITY"
        ]
        assert codes(client.command("blue", [ssl.global_velocity(1, 0.0, 0.0, math.inf)])) == [
            "INVALID_VELOCITY"
        ]
        assert codes(client.command("blue", [ssl.local_velocity(0, 0.0, 0.0, kick_speed=9.0)])) == [
            "KICK_OVER_LIMIT"
        ]
        mixed = client.command(
            "yellow",
            [ssl.local_velocity(9, 0.0, 0.0), ssl.local_velocity(3, 0.2, 0.0, kick_speed=20.0)],
        )
        assert codes(mixed) == ["UNKNOWN_ROBOT", "KICK_OVER_LIMIT"]
        assert [e.message for e in mixed.errors][1].startswith("yellow 3:")

        # Still answering, and still simulating.
        for team in ("blue", "yellow"):
            r = client.command(team, [ssl.local_velocity(i, 0.0, 0.0) for i in range(6)])
            assert codes(r) == [] and len(r.feedback) == 6
        assert codes(client.teleport_ball(1.0, 1.0)) == []
        settle(vision, 0.2)
        assert vision.state.ball is not None
        assert math.hypot(vision.state.ball[0] - 1000, vision.state.ball[1] - 1000) < 1.0
        assert referee.poll() is not None


# Run in .venv-sslvision: pySSLVision's receiving thread, its callback and its
# `assign_empty_values` (field-relative metres: origin at the field's corner). Its socket joins
# a multicast group; the test's simulator sends to 127.0.0.1, so only the socket is replaced.
SSLVISION_CLIENT = r'''
import json, socket, sys, threading
from pySSLVision.VisionComm import SSLVision, assign_empty_values

config, wanted = sys.argv[1], int(sys.argv[2])


class LoopbackVision(SSLVision):
    def _create_socket(self):
        sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM, socket.IPPROTO_UDP)
        sock.bind((self.host, self.vision_port))
        print("PORT", sock.getsockname()[1], flush=True)
        return sock


vision = LoopbackVision(config)
vision.daemon = True
frames, go, done = [], threading.Event(), threading.Event()


def on_frame():
    if go.is_set() and not done.is_set():
        frame = assign_empty_values(vision.frame, (9.0, 6.0), "left")
        if frame is not None:
            frames.append(frame)
        if len(frames) >= wanted:
            done.set()


vision.assign_vision(on_frame)
vision.start()
sys.stdin.readline()
go.set()
ok = done.wait(10.0)
print(json.dumps({"ok": ok, "alive": vision.is_alive(), "frames": frames}), flush=True)
'''


def test_pysslvision_reads_the_realistic_vision(binary, sslvision_python, tmp_path):
    # The league's geometry packet of this field (1039 bytes) does not fit pySSLVision's
    # 1024-byte reads: its thread dies on one. The first is sent before any detection, which
    # its start-up read takes whole; none comes after.
    text = SCENARIO.read_text()
    assert "[ssl.vision]\n" in text
    scenario = tmp_path / "ssl_match.toml"
    text = text.replace("[ssl.vision]\n", "[ssl.vision]\ngeometry_period_s = 1e6\n", 1)
    scenario.write_text(text)
    config = tmp_path / "config.json"
    config.write_text(json.dumps({"network": {"multicast_ip": "127.0.0.1", "vision_port": 0}}))
    script = tmp_path / "sslvision_client.py"
    script.write_text(SSLVISION_CLIENT)
    env = {k: v for k, v in os.environ.items() if k not in ("VISION_PORT", "MULTICAST_IP")}
    client = subprocess.Popen(
        [sslvision_python, str(script), str(config), "240"],
        stdin=subprocess.PIPE,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env=env,
    )
    try:
        port = None
        for line in client.stdout:
            if line.startswith("PORT "):
                port = int(line.split()[1])
                break
        assert port, client.stderr.read()
        truth = {}
        for k in range(6):
            truth[("blue", k)] = (-3.5 + 1.4 * k, 1.2, 0.4 * k - 1.0)
            truth[("yellow", k)] = (-3.5 + 1.4 * k, -1.3, 2.5 - 0.5 * k)
        ball = (0.8, 0.1)
        with ssl.serve(
            scenario,
            extra_args=["--no-cameras", "--realism", "--no-referee"],
            binary=binary,
            vision=("127.0.0.1", port),
        ) as served, served.client() as sim:
            places = [(t, k, x, y, o, True) for (t, k), (x, y, o) in truth.items()]
            assert ssl.error_codes(sim.teleport_robots(places)) == []
            assert ssl.error_codes(sim.teleport_ball(*ball)) == []
            time.sleep(0.2)  # past vision's 35 ms delay
            out, err = client.communicate("go\n", timeout=30)
    finally:
        if client.poll() is None:
            client.kill()
    result = json.loads(out.strip().splitlines()[-1])
    assert result["ok"] and result["alive"], err[-2000:]
    frames = result["frames"]
    assert len(frames) >= 240

    # pySSLVision's frame: metres from the field's corner (team side "left").
    def mm(p):
        return (p["x"] - 4.5) * 1000.0, (p["y"] - 3.0) * 1000.0

    seen = {key: [] for key in truth}
    balls = []
    for f in frames:
        for team, key in (("blue", "robotsBlue"), ("yellow", "robotsYellow")):
            for r in f.get(key, []):
                seen[(team, r["robotId"])].append((*mm(r), r["orientation"]))
        if f.get("balls"):
            balls.append(mm(f["ball"]))
    # ER-Force's realistic noise: 1.3 mm and 0.01 rad on robots, 1.4 mm on the ball; within
    # five sigma each, the means within a millimetre.
    for key, (x, y, o) in truth.items():
        assert seen[key], f"pySSLVision never saw {key}"
        errors = [math.hypot(sx - 1000 * x, sy - 1000 * y) for sx, sy, _ in seen[key]]
        assert max(errors) < 7.0, (key, max(errors))
        mean = (
            sum(s[0] for s in seen[key]) / len(seen[key]) - 1000 * x,
            sum(s[1] for s in seen[key]) / len(seen[key]) - 1000 * y,
        )
        assert math.hypot(*mean) < 1.0, (key, mean)
        worst = max(abs((so - o + math.pi) % (2 * math.pi) - math.pi) for *_, so in seen[key])
        assert worst < 0.05, (key, worst)
    assert balls, "pySSLVision never saw the ball"
    errors = [math.hypot(bx - 1000 * ball[0], by - 1000 * ball[1]) for bx, by in balls]
    assert max(errors) < 7.5, max(errors)
    # Noise, not the truth copied out: the detections differ.
    assert len({round(e, 3) for e in errors}) > len(errors) // 2


def lockstep_run(binary: str, out: Path):
    """A fixed command stream in lockstep: each step's detection frames, and where vision saw
    the ball after the first step and after the last."""
    vision, referee = ssl.VisionReceiver(), ssl.RefereeReceiver()
    frames, seen, balls = [], ssl.VisionState(), []
    with ssl.serve(
        SCENARIO,
        lockstep=True,
        extra_args=["--no-cameras", "--idle-exit-s", "1", "--seed", "7"],
        binary=binary,
        out=out,
        vision=vision.address,
        referee=referee.address,
    ) as served, served.client() as client:
        setup = ssl.SimulatorCommand()
        setup.control.teleport_ball.x, setup.control.teleport_ball.y = -0.4, 0.3
        kicker = setup.control.teleport_robot.add()
        kicker.id.id, kicker.id.team = 3, ssl.Team.BLUE
        kicker.x, kicker.y, kicker.orientation = -0.7, 0.3, 0.0
        r = client.sync("control", 0.0, simulator_command=setup)
        assert ssl.error_codes(r) == [] and r.detection == []
        for step in range(300):
            yellow = [ssl.global_velocity(i, -0.4, 0.3 * (i - 2.5), 0.5) for i in range(6)]
            assert ssl.error_codes(client.command("yellow", yellow)) == []
            blue = [ssl.local_velocity(i, 0.6, 0.1 * i, -0.2) for i in range(6) if i != 3]
            blue.append(ssl.local_velocity(3, 0.8, 0.0, kick_speed=3.0))
            r = client.sync("blue", 0.01, blue)
            assert ssl.error_codes(r) == []
            assert len(r.robot_control_response.feedback) == 6
            frames += [f.SerializeToString() for f in r.detection]
            for f in r.detection:
                seen.update(f)
            if step in (0, 299):
                balls.append(seen.ball)
        assert served.wait(30) == 0, served.stderr()
    vision.close()
    referee.close()
    return frames, balls


def test_lockstep_runs_repeat_byte_for_byte(binary, tmp_path):
    runs = [tmp_path / "a", tmp_path / "b"]
    (frames_a, balls), (frames_b, _) = (lockstep_run(binary, out) for out in runs)
    assert frames_a == frames_b
    frames = [frames_a]
    assert len(frames[0]) == 300 * 4  # four cameras, a frame each every cycle
    names = ["ssl.log", "trajectory.csv", "ball.csv"]
    names += [str(p.relative_to(runs[0])) for p in sorted(runs[0].glob("robots/*/trajectory.csv"))]
    assert len(names) == 3 + 12
    for name in names + ["events.jsonl"]:
        a, b = (run / name for run in runs)
        assert a.stat().st_size > 0 or name == "events.jsonl", name
        assert a.read_bytes() == b.read_bytes(), name
    # The kick happened: the ball left its place toward +x.
    assert balls[0] is not None and balls[1] is not None
    assert balls[1][0] - balls[0][0] > 500, balls


def test_the_scripted_match_scores_without_errors(binary):
    """python/examples/ssl_match.py in lockstep, until the first goal (60 s of play at most):
    no SimulatorError answered, and the referee counted the goal."""
    out = subprocess.run(
        [
            sys.executable,
            str(ROOT / "python" / "examples" / "ssl_match.py"),
            "--serve",
            "--binary",
            binary,
            "--goals",
            "1",
            "--json",
        ],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert out.returncode == 0, out.stderr
    result = json.loads(out.stdout.strip().splitlines()[-1])
    assert result["errors"] == 0, result["error_codes"]
    assert result["blue"] + result["yellow"] == len(result["goals"]) == 1, result
    assert result["simulated_s"] < 60.0, result
