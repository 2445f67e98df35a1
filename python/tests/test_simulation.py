"""`omniloop.Simulation`: Python as the robot's software, truth kept apart, bad input refused."""

import math

import numpy as np
import pytest

import omniloop
from conftest import SCENARIOS, goal_in_body, to_goal


def test_an_observation_holds_what_the_sensors_give(corner):
    sim = omniloop.Simulation(corner)
    obs = sim.reset()
    assert obs.t_s == 0.0 and obs.cycle == 0 and not obs.done
    (name, image), = obs.frames.items()
    assert name == corner.robot["sensors"][0]["name"]
    assert image.shape == (220, 256, 3) and image.dtype == np.uint8
    assert obs.odometry.dt_s == 0.0
    obs = sim.step((200.0, 0.0, 0.0))
    assert obs.cycle == 1 and obs.t_s == pytest.approx(corner.control_period_s)
    assert obs.odometry.dt_s == pytest.approx(corner.control_period_s)
    assert obs.odometry.vx_mm_s > 0.0
    assert obs.estimates is None
    # The truth is the simulator's: no pose, contacts or goal flag in an observation.
    public = {a for a in dir(obs) if not a.startswith("_")}
    # What the robot's sensors give, the light barrier of a dribbler among them; no truth.
    assert public == {
        "t_s", "cycle", "frames", "odometry", "odometry_pose", "actuators", "ball_in_dribbler",
        "done", "estimates",
    }
    truth = sim.truth()
    assert truth["x_mm"] > corner.robot["start"][0]
    assert truth["contacts"] == 0 and truth["reached_goal"] is False


def test_same_seed_and_commands_give_the_same_frames_bit_for_bit(corner):
    def frames(seed):
        sim = omniloop.Simulation(corner, seed=seed)
        out = [sim.reset().frames["omni"]]
        for k in range(6):
            out.append(sim.step((300.0, 40.0 * k, 0.1)).frames["omni"])
        return out, sim.truth()

    a, ta = frames(21)
    b, tb = frames(21)
    c, _ = frames(22)
    assert all(np.array_equal(x, y) for x, y in zip(a, b))
    assert ta == tb
    assert not np.array_equal(a[3], c[3]), "another seed draws other sensor noise"


def test_reset_starts_again_with_the_seed_asked(corner):
    sim = omniloop.Simulation(corner, seed=4)
    first = sim.reset().frames["omni"]
    sim.step((300.0, 0.0, 0.0))
    assert sim.cycle == 1
    again = sim.reset()
    assert sim.cycle == 0 and np.array_equal(again.frames["omni"], first)
    other = sim.reset(seed=5)
    assert sim.seed == 5 and not np.array_equal(other.frames["omni"], first)


def test_builtin_robot_stepped_to_the_end_is_the_run(corner, tmp_path):
    whole = omniloop.run(corner, renderer="cpu")
    sim = omniloop.Simulation(corner, robot="builtin")
    obs = sim.reset()
    records = 0
    while not obs.done:
        obs = sim.step()
        assert obs.estimates is not None and "truth" not in obs.estimates
        records += 1
    assert sim.record()["truth"]["x_mm"] == pytest.approx(sim.trajectory()["x_mm"][-2])
    stepped = sim.trajectory()
    for name in whole.trajectory:
        np.testing.assert_array_equal(stepped[name], whole.trajectory[name], err_msg=name)
    summary = sim.summary()
    assert summary["reached_goal"] is True and summary["wall_contacts"] == 0
    assert summary["cycles"] == records == whole.summary["cycles"]
    assert summary["turn_onset_mm"] == whole.summary["turn_onset_mm"]
    sim.write(tmp_path)
    omniloop.run(corner, out=tmp_path / "cli")
    assert (tmp_path / "trajectory.csv").read_bytes() == (
        tmp_path / "cli" / "trajectory.csv"
    ).read_bytes()


def test_a_python_robot_reaches_the_smoke_goal_on_dead_reckoning(smoke, tmp_path):
    goal = (smoke.robot["goal"]["x_mm"], smoke.robot["goal"]["y_mm"])
    sim = omniloop.Simulation(smoke)
    obs = sim.reset()
    while not obs.done:
        obs = sim.step(to_goal(goal_in_body(obs, goal)), estimate=obs.odometry_pose)
    summary = sim.summary()
    assert summary["controller"] == "python"
    assert summary["reached_goal"] is True and summary["wall_contacts"] == 0
    sim.write(tmp_path)
    header = (tmp_path / "trajectory.csv").read_text().splitlines()[1].split(",")
    assert header[8] != "", "the estimate Python gave is recorded"


def test_pan_commands_move_the_pan_unit(pinhole):
    sim = omniloop.Simulation(pinhole)
    obs = sim.reset()
    assert obs.actuators == {"front": 0.0}
    for _ in range(5):
        obs = sim.step((0.0, 0.0, 0.0), actuators=[{"sensor": "front", "rate_rad_s": 0.5}])
    assert obs.actuators["front"] > 0.0
    obs = sim.step((0.0, 0.0, 0.0), actuators=[{"sensor": "front", "pan_rad": 0.0}])
    assert obs.actuators["front"] < 5 * 0.5 * pinhole.control_period_s


def test_a_differential_robot_takes_speed_and_turn_rate(smoke):
    diff = smoke.with_values({"robot.differential.track_mm": 120.0})
    sim = omniloop.Simulation(diff)
    sim.reset()
    with pytest.raises(ValueError, match=r"differential robot takes \(v_mm_s, omega_rad_s\)"):
        sim.step((100.0, 0.0, 0.0))
    for _ in range(5):
        obs = sim.step((200.0, 0.3))
    assert obs.odometry.vx_mm_s > 0.0 and obs.odometry.omega_rad_s > 0.0


@pytest.mark.parametrize(
    "command, message",
    [
        ((math.nan, 0.0, 0.0), r"command\[0\] is NaN"),
        ((0.0, math.inf, 0.0), r"command\[1\] is inf"),
        ((1.0, 2.0), "omnidirectional robot takes"),
        ((1.0, 2.0, 3.0, 4.0), "omnidirectional robot takes"),
        ("fast", "sequence of numbers"),
        (np.zeros((3, 3)), "sequence of numbers"),
        (None, "needs a command"),
    ],
)
def test_bad_commands_raise_value_error(corner, command, message):
    sim = omniloop.Simulation(corner)
    with pytest.raises(ValueError, match=message):
        sim.step(command)
    assert sim.cycle == 0, "nothing ran"


def test_bad_actuators_and_options_raise(pinhole, corner):
    sim = omniloop.Simulation(pinhole)
    with pytest.raises(ValueError, match="no pan unit carries camera \"rear\""):
        sim.step((0.0, 0.0, 0.0), actuators=[{"sensor": "rear", "pan_rad": 1.0}])
    with pytest.raises(ValueError, match="must be finite"):
        sim.step((0.0, 0.0, 0.0), actuators=[{"sensor": "front", "pan_rad": math.nan}])
    with pytest.raises(ValueError, match="actuators must be"):
        sim.step((0.0, 0.0, 0.0), actuators=[{"sensor": "front"}])
    with pytest.raises(ValueError, match="renderer"):
        omniloop.Simulation(corner, renderer="film")
    with pytest.raises(ValueError, match="robot="):
        omniloop.Simulation(corner, robot="someone")
    with pytest.raises(ValueError, match="decides its own commands"):
        omniloop.Simulation(corner, robot="builtin").step((1.0, 0.0, 0.0))
    with pytest.raises(ValueError, match="a top view is 200 to 4000 pixels wide"):
        sim.topview(width=10)


def test_stepping_a_finished_run_raises_runtime_error(pinhole):
    sim = omniloop.Simulation(pinhole)
    obs = sim.reset()
    while not obs.done:
        obs = sim.step((0.0, 0.0, 0.0))
    assert obs.frames["front"].shape == (240, 320, 3), "the last state is seen too"
    with pytest.raises(RuntimeError, match="the run is over"):
        sim.step((0.0, 0.0, 0.0))
    assert not sim.reset().done


def test_an_experiment_with_its_own_procedure_is_refused():
    scenario = omniloop.Scenario.load(SCENARIOS / "selfloc_field.toml")
    with pytest.raises(omniloop.ScenarioError, match="cannot be stepped from outside"):
        omniloop.Simulation(scenario)


def test_topview_is_an_rgb_image(smoke):
    sim = omniloop.Simulation(smoke)
    sim.reset()
    sim.step((300.0, 0.0, 0.0))
    image = sim.topview(width=400)
    assert image.dtype == np.uint8 and image.shape[1] == 400 and image.shape[2] == 3
    assert image.min() < 100 < image.max()


def gpu_or_skip(make):
    """Builds with the GPU renderer; skips without an adapter unless CI requires the GPU."""
    import os

    try:
        return make()
    except omniloop.RenderError as e:
        if os.environ.get("OMNILOOP_REQUIRE_GPU"):
            raise
        pytest.skip(f"no GPU adapter: {e}")


def test_a_vector_on_the_gpu_traces_in_shared_batches_what_each_run_sees_alone(corner):
    vec = gpu_or_skip(lambda: omniloop.VectorSimulation(corner, 2, seed=8, renderer="gpu"))
    alone = [omniloop.Simulation(corner, seed=8 + i, renderer="gpu") for i in range(2)]
    first = vec.observe()
    for i in range(2):
        assert np.array_equal(first[i].frames["omni"], alone[i].reset().frames["omni"])
    commands = [(250.0, 0.0, 0.0), (200.0, 50.0, 0.1)]
    for _ in range(3):
        together = vec.step(commands)
        apart = [sim.step(c) for sim, c in zip(alone, commands)]
    for i in range(2):
        assert np.array_equal(together[i].frames["omni"], apart[i].frames["omni"])
    assert vec.truth() == [sim.truth() for sim in alone]
