"""What the ROS 2 bridge puts on its topics, checked without ROS: SI units, the scan from the
free-space stage, the camera model as camera_info, the odometry's covariance, cmd_vel's limits;
and the bridge's command line on bad input."""

import math
import subprocess
import sys

import numpy as np
import pytest

import omniloop
from omniloop.ros import mapping

from conftest import SCENARIOS


def test_stamps_are_simulation_time_to_the_nanosecond():
    assert mapping.stamp(0.0) == (0, 0)
    assert mapping.stamp(3.84) == (3, 840_000_000)
    sec, ns = mapping.stamp(1234.56789)
    assert abs(mapping.seconds(sec, ns) - 1234.56789) < 1e-9


def test_a_rotation_matrix_comes_back_from_its_quaternion():
    rng = np.random.default_rng(3)
    for _ in range(20):
        q = rng.normal(size=4)
        x, y, z, w = q / np.linalg.norm(q)
        r = np.array(
            [
                [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
            ]
        )
        got = np.array(mapping.matrix_quaternion(r))
        assert min(np.abs(got - [x, y, z, w]).max(), np.abs(got + [x, y, z, w]).max()) < 1e-12


def test_cmd_vel_is_clipped_to_the_robots_speed_and_a_nan_refused(corner):
    robot = corner.robot  # max 400 mm/s
    vx, vy, w = mapping.body_command(3.0, 4.0, 0.5, robot)
    assert math.hypot(vx, vy) == pytest.approx(robot["max_speed_mm_s"])
    assert vy / vx == pytest.approx(4.0 / 3.0) and w == 0.5
    assert mapping.body_command(0.1, -0.2, 0.0, robot) == pytest.approx((100.0, -200.0, 0.0))
    with pytest.raises(mapping.CommandError, match="not finite"):
        mapping.body_command(float("nan"), 0.0, 0.0, robot)
    diff = dict(robot, differential={"track_mm": 150.0, "max_turn_rate_rad_s": 1.0})
    assert mapping.body_command(0.2, 0.3, -5.0, diff) == pytest.approx((200.0, -1.0))


def test_a_command_older_than_the_timeout_stops_the_robot():
    stop, go = (0.0, 0.0, 0.0), (300.0, 0.0, 0.1)
    assert mapping.command_at(go, 1.0, 1.5, 0.5, stop) == go
    assert mapping.command_at(go, 1.0, 1.54, 0.5, stop) == stop
    assert mapping.command_at(go, -math.inf, 0.0, 0.5, stop) == stop  # none yet


def test_the_odometry_covariance_grows_along_the_path_and_across_it_with_the_heading_noise():
    cov = mapping.OdometryCovariance.from_spec(
        {
            "speed_noise_frac": 0.01,
            "omega_noise_rad_s": 0.01,
            "scale_bias_frac": 0.0,
            "omega_bias_rad_s": 0.0,
            "slip_s": 0.0,
        }
    )
    for _ in range(100):  # 4 s straight along x at 0.5 m/s
        cov.update(500.0, 0.0, 0.0, 0.04, 0.0)
    p = cov.pose
    # Along: 100 readings of (0.01 * 0.5 * 0.04)^2 each.
    assert p[0, 0] == pytest.approx(100 * (0.01 * 0.5 * 0.04) ** 2)
    # Across: the heading's error, accumulated, times the distance still to drive.
    assert p[1, 1] > p[0, 0] and p[2, 2] == pytest.approx(100 * (0.01 * 0.04) ** 2)
    six = np.array(cov.pose_6x6()).reshape(6, 6)
    assert six[0, 0] == p[0, 0] and six[5, 5] == p[2, 2] and six[1, 5] == p[1, 2]
    assert np.allclose(six, six.T)


def test_the_scan_is_the_free_space_stage_of_the_built_in_robot(corner):
    """The detector the bridge runs on each frame gives the built-in robot's free-space stage's
    distances (its estimates record) for the same frames, and the scan carries them in metres,
    +inf where a direction is free to the template's edge."""
    sim = omniloop.Simulation(corner, robot="builtin")
    detector = sim.free_space_detector()
    assert detector.camera == "omni"
    obs = sim.reset()
    free_seen = 0
    for _ in range(40):
        frame = obs.frames["omni"]
        obs = sim.step()
        stage = np.array(sim.record()["free_mm"])
        mine = detector.detect(frame)
        assert np.array_equal(mine["free_mm"], stage)
        scan = mapping.free_space_scan(mine)
        free = mine["free_mm"] >= mine["range_mm"]
        free_seen += int(free.sum())
        assert np.all(np.isinf(np.array(scan.ranges)[free]))
        finite = np.array(scan.ranges)[~free]
        assert np.allclose(finite, mine["free_mm"][~free] / 1000.0, rtol=1e-6)
    assert 0 < free_seen < 40 * 32  # the corner's walls block some directions, not all
    assert scan.angle_increment == pytest.approx(2 * math.pi / 32)
    assert (scan.range_min, scan.range_max) == pytest.approx((0.2, 1.0))


def test_camera_info_carries_the_fitted_unified_model_and_a_pinhole_camera(corner, pinhole):
    model = corner.camera_model()
    info = mapping.camera_info(model)
    assert info.distortion_model == "omnidir_mei" and len(info.d) == 5
    assert info.d[4] == model["intrinsics"]["xi"] and 0.9 < info.d[4] < 1.0
    assert (info.width, info.height) == (256, 220)
    assert model["model_frame_in_body"]["translation_mm"][2] == pytest.approx(205.08)
    pin = pinhole.camera_model()
    pinfo = mapping.camera_info(pin)
    assert pinfo.distortion_model == "plumb_bob" and pinfo.d == [0.0] * 5
    assert pinfo.k[0] == pinfo.k[4] == pin["intrinsics"]["focal_px"][0]
    with pytest.raises(ValueError, match="no robot"):
        corner.camera_model(robot="nobody")


def test_a_pinhole_cameras_optical_frame_looks_along_its_axis_with_the_image_right_to_its_right(
    pinhole,
):
    """REP-103's optical frame: z along the optical axis (25 degrees down, pan 0), x to the
    image's right (the robot's right), y down the image; a rotation (orthonormal, det +1)."""
    model = pinhole.camera_model()
    r = np.array(model["model_frame_in_body"]["rotation"])
    tilt = math.radians(-25.0)
    assert np.allclose(r[:, 2], [math.cos(tilt), 0.0, math.sin(tilt)])
    assert np.allclose(r[:, 0], [0.0, -1.0, 0.0])
    assert r[2, 1] < 0  # y points down
    assert np.allclose(r.T @ r, np.eye(3)) and np.linalg.det(r) == pytest.approx(1.0)
    assert model["pan_unit"] and model["pan_rad"] == 0.0
    turned = np.array(mapping.panned(r, math.pi / 2))
    assert np.allclose(turned[:, 2], [0.0, math.cos(tilt), math.sin(tilt)])  # now looks left
    q = mapping.matrix_quaternion(turned)
    assert abs(sum(c * c for c in q) - 1.0) < 1e-12


def test_a_bad_scenario_exits_2_with_the_command_lines_message(tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text('seed = "x"\n')
    r = subprocess.run(
        [sys.executable, "-m", "omniloop.ros.cli", str(bad)], capture_output=True, text=True
    )
    assert r.returncode == 2
    assert f"{bad}:1:8: field `seed`: invalid type" in r.stderr


def test_without_ros_2_one_line_says_how_to_install_it():
    code = (
        "import sys; sys.modules['rclpy'] = None\n"
        "from omniloop.ros.cli import main\n"
        f"sys.exit(main([{str(SCENARIOS / 'ros_smoke.toml')!r}]))"
    )
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert r.returncode == 1
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and "pip install 'omniloop[ros]'" in lines[0]


def test_the_written_out_covariance_update_is_the_matrix_form():
    """``P' = F P F^T + G Q G^T`` with the Jacobians as matrices, against the update's own."""
    rng = np.random.default_rng(1)
    cov = mapping.OdometryCovariance(speed_frac=0.02, omega_rad_s=0.03)
    p = np.zeros((3, 3))
    for _ in range(50):
        vx, vy, th, dt = rng.normal(300, 200), rng.normal(0, 200), rng.uniform(-3, 3), 0.04
        cov.update(vx, vy, rng.normal(), dt, th)
        q = np.diag([(0.02 * vx / 1000) ** 2, (0.02 * vy / 1000) ** 2, 0.03**2])
        c, s = math.cos(th), math.sin(th)
        f = np.array(
            [
                [1, 0, (-s * vx - c * vy) / 1000 * dt],
                [0, 1, (c * vx - s * vy) / 1000 * dt],
                [0, 0, 1],
            ]
        )
        g = np.array([[c * dt, -s * dt, 0], [s * dt, c * dt, 0], [0, 0, dt]])
        p = f @ p @ f.T + g @ q @ g.T
    assert np.abs(cov.pose - p).max() < 1e-12 * np.abs(p).max()


KICKER = {"max_kick_mm_s": 6500.0, "full_pull_rpm": 5000.0, "front_mm": 75.0}


def test_a_kick_is_its_velocity_in_base_link_and_a_bad_one_refused():
    assert mapping.kick_command(5.0, 0.0, 0.0, KICKER) == {"kick_mm_s": 5000.0, "angle_rad": 0.0}
    chip = mapping.kick_command(3.0, 0.0, 3.0, KICKER)
    assert chip["kick_mm_s"] == pytest.approx(3000.0 * math.sqrt(2.0))
    assert chip["angle_rad"] == pytest.approx(math.pi / 4)
    assert mapping.kick_command(0.0, 0.0, 0.0, KICKER) == {"kick_mm_s": 0.0, "angle_rad": 0.0}
    # The limit itself is taken; a hair over it by rounding is taken as the limit.
    assert mapping.kick_command(6.5, 0.0, 0.0, KICKER)["kick_mm_s"] == 6500.0
    assert mapping.kick_command(6.5 + 1e-12, 0.0, 0.0, KICKER)["kick_mm_s"] == 6500.0
    for bad, why in [
        ((7.0, 0.0, 0.0), "over the kicker's limit of 6.5 m/s"),
        ((5.0, 0.0, 5.0), "over the kicker's limit"),
        ((float("nan"), 0.0, 0.0), "not finite"),
        ((1.0, 0.0, float("inf")), "not finite"),
        ((-1.0, 0.0, 0.0), "never back"),
        ((1.0, 0.0, -0.5), "never back, down"),
        ((1.0, 0.5, 0.0), "aside"),
        ((0.0, 0.0, 2.0), "straight up"),
        ((1e-300, 0.0, 2.0), "straight up"),
    ]:
        with pytest.raises(mapping.CommandError, match=why):
            mapping.kick_command(*bad, KICKER)
    with pytest.raises(mapping.CommandError, match="no kicker"):
        mapping.kick_command(1.0, 0.0, 0.0, None)


def test_a_dribbler_speed_is_in_rpm_and_a_bad_one_refused():
    assert mapping.dribbler_command(3000.0, KICKER) == {"dribbler_rpm": 3000.0}
    assert mapping.dribbler_command(0.0, KICKER) == {"dribbler_rpm": 0.0}
    for bad in (-1.0, float("nan"), float("inf")):
        with pytest.raises(mapping.CommandError, match="finite number >= 0"):
            mapping.dribbler_command(bad, KICKER)
    with pytest.raises(mapping.CommandError, match="no dribbler"):
        mapping.dribbler_command(100.0, None)


def test_every_kick_the_mapping_takes_is_one_the_simulation_takes():
    """What ``kick_command`` lets through, ``Simulation.step`` fires without a ValueError (the
    node would stop on one), at the limit and just under straight up included."""
    scenario = omniloop.Scenario.load(SCENARIOS / "ball_rollout.toml")
    kicker = scenario.robot["kicker"]
    assert kicker is not None and kicker["max_kick_mm_s"] == 6500.0
    sim = omniloop.Simulation(scenario)
    sim.reset(seed=1)
    for v in [(6.5, 0.0, 0.0), (6.5 + 1e-12, 0.0, 0.0), (1e-9, 0.0, 6.5), (0.0, 0.0, 0.0)]:
        sim.step((0.0, 0.0, 0.0), actuators=[mapping.kick_command(*v, kicker)])
    sim.step((0.0, 0.0, 0.0), actuators=[mapping.dribbler_command(0.0, kicker)])


def test_the_balls_truth_is_in_metres():
    ball = {"x_mm": 1500.0, "y_mm": -250.0, "z_mm": 21.5, "vx_mm_s": 3000.0, "vy_mm_s": -40.0,
            "vz_mm_s": 0.0}
    state = mapping.ball_state(ball)
    assert state.position == pytest.approx((1.5, -0.25, 0.0215))
    assert state.velocity == pytest.approx((3.0, -0.04, 0.0))
