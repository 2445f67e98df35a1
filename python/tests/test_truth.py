"""The truth beside each frame from Python: `Simulation(truth=True).truth_frames()`, the
Gymnasium option that puts it in `info` (never in the observation), and a truth dataset
written with `omniloop.write_dataset` and read back with `omniloop.dataset.load`."""

import numpy as np
import pytest

import omniloop
from omniloop import dataset
from conftest import SCENARIOS

FLOOR_CLASSES = {"floor_region", "floor_line", "floor_mark", "floor_outside"}


def labels_of(legend, classes):
    return np.array([e["label"] for e in legend if e["class"] in classes], dtype=np.uint16)


def test_truth_frames_are_arrays_beside_each_frame(corner):
    sim = omniloop.Simulation(corner, truth=True)
    obs = sim.reset()
    truth = sim.truth_frames()
    assert set(truth) == set(obs.frames) == {"omni"}
    t = truth["omni"]
    assert set(t) == {"depth_mm", "floor_mm", "labels", "legend"}
    for key, dtype in (("depth_mm", np.float32), ("floor_mm", np.float32), ("labels", np.uint16)):
        assert t[key].shape == (220, 256) and t[key].dtype == dtype, key
    legend = t["legend"]
    assert [e["label"] for e in legend] == list(range(len(legend)))
    assert set(legend[0]) == {"label", "class", "instance", "name", "rgb"}
    assert int(t["labels"].max()) < len(legend)
    sim.step((300.0, 0.0, 0.2))
    assert sim.truth_frames()["omni"]["depth_mm"].shape == (220, 256)


def test_floor_distance_is_finite_exactly_on_floor_pixels(corner):
    sim = omniloop.Simulation(corner, truth=True)
    sim.reset()
    t = sim.truth_frames()["omni"]
    floor = np.isin(t["labels"], labels_of(t["legend"], FLOOR_CLASSES))
    assert floor.sum() > 1000, "the mirror sees the floor around the robot"
    assert np.isfinite(t["floor_mm"][floor]).all() and (t["floor_mm"][floor] > 0).all()
    assert np.isnan(t["floor_mm"][~floor]).all()
    sky = np.isin(t["labels"], labels_of(t["legend"], {"sky"}))
    nothing = np.isin(t["labels"], labels_of(t["legend"], {"nothing"}))
    assert np.isposinf(t["depth_mm"][sky]).all()
    assert np.isnan(t["depth_mm"][nothing]).all(), "no mirror there"
    seen = ~(sky | nothing)
    assert np.isfinite(t["depth_mm"][seen]).all() and (t["depth_mm"][seen] > 0).all()


def test_the_same_seed_gives_the_same_truth(corner):
    def truth(seed):
        sim = omniloop.Simulation(corner, seed=seed, truth=True)
        sim.reset(seed=seed)
        for k in range(3):
            sim.step((300.0, 50.0 * k, 0.1))
        return sim.truth_frames()["omni"]

    a, b = truth(4), truth(4)
    for key in ("depth_mm", "floor_mm", "labels"):
        np.testing.assert_array_equal(a[key], b[key])
    assert a["legend"] == b["legend"]


def test_truth_frames_need_truth_true_and_it_stays_across_reset(corner):
    sim = omniloop.Simulation(corner)
    sim.reset()
    with pytest.raises(ValueError, match="truth=True"):
        sim.truth_frames()
    sim = omniloop.Simulation(corner, truth=True)
    sim.reset(seed=9)
    assert "omni" in sim.truth_frames()
    with pytest.raises(ValueError, match="no robot"):
        sim.truth_frames(robot="nobody")
    assert set(sim.truth_frames(robot="robot")) == {"omni"}


def test_gym_puts_the_truth_frames_in_info_never_in_the_observation(corner):
    gym = pytest.importorskip("omniloop.gym")
    import gymnasium

    env = gymnasium.make(gym.ENV_ID, scenario=corner, truth_frames=True)
    obs, info = env.reset(seed=1)
    assert "truth_frames" not in obs and set(obs) == {"omni", "odometry", "goal"}
    assert info["truth_frames"]["omni"]["labels"].shape == (220, 256)
    obs, _, _, _, info = env.step(env.action_space.sample())
    assert "truth_frames" not in obs
    assert info["truth_frames"]["omni"]["depth_mm"].dtype == np.float32
    _, info = gym.OmniloopEnv(corner).reset(seed=1)
    assert "truth_frames" not in info


def test_the_vector_env_gives_each_run_its_truth_frames(corner):
    gym = pytest.importorskip("omniloop.gym")
    env = gym.make_vec(corner, num_envs=2, truth_frames=True)
    obs, info = env.reset(seed=3)
    assert "truth_frames" not in obs
    assert len(info["truth_frames"]) == 2 and info["_truth_frames"].all()
    assert info["truth_frames"][1]["omni"]["floor_mm"].shape == (220, 256)
    _, _, _, _, info = env.step(env.action_space.sample())
    assert info["truth_frames"][0]["omni"]["labels"].dtype == np.uint16


@pytest.fixture(scope="module")
def written(tmp_path_factory):
    out = tmp_path_factory.mktemp("dataset")
    scenario = SCENARIOS / "corner55_velocity_aware.toml"
    info = omniloop.write_dataset(scenario, out, samples=5, poses="random", seed=2)
    return out, info


def test_a_written_dataset_reads_back(written):
    out, info = written
    assert info["format"] == "omniloop-truth-dataset" and info["samples"] == 5
    assert info["size_px"] == [256, 220] and info["poses"] == "random"
    ds = dataset.load(out)
    assert len(ds) == 5 and ds.info == info and ds.poses.shape == (5, 3)
    assert ds.camera_model is not None and ds.camera_model.is_file()
    assert ds.calibration is None or ds.calibration.is_file()
    seen = [s["pose"] for s in ds]
    assert len(seen) == 5 and len(set(seen)) == 5, "random poses differ"
    sample = ds[-1]
    assert sample["image"].shape == (220, 256, 3) and sample["image"].dtype == np.uint8
    assert sample["depth_mm"].shape == (220, 256) and sample["depth_mm"].dtype == np.float32
    assert sample["labels"].shape == (220, 256) and sample["labels"].dtype == np.uint8
    assert sample["t_s"] == 0.0 and sample["pose"] == tuple(ds.poses[4])
    with pytest.raises(IndexError):
        ds[5]


def test_dataset_depth_and_labels_agree_with_the_legend(written):
    ds = dataset.load(written[0])
    sky_or_nothing = labels_of(ds.legend, {"sky", "nothing"})
    for sample in ds:
        labels, depth = sample["labels"], sample["depth_mm"]
        assert int(labels.max()) < len(ds.legend)
        seen = ~np.isin(labels, sky_or_nothing)
        assert seen.sum() > 1000
        assert np.isfinite(depth[seen]).all() and (depth[seen] > 0).all()
        assert np.isnan(depth[~seen]).all(), "the file's 0: sky or no mirror"
        assert (depth[seen] == np.round(depth[seen])).all(), "whole millimetres"


def test_bad_files_raise_naming_the_file(tmp_path, written):
    with pytest.raises(FileNotFoundError, match="nothing.png"):
        omniloop._omniloop.read_png_levels(tmp_path / "nothing.png")
    bad = tmp_path / "bad.png"
    bad.write_bytes(b"not a png")
    with pytest.raises(ValueError, match="bad.png"):
        omniloop._omniloop.read_png_levels(bad)
    with pytest.raises(ValueError, match="bad.png"):
        omniloop._omniloop.read_png_rgb(bad)
    with pytest.raises(ValueError, match="dataset.json"):
        (tmp_path / "dataset.json").write_text('{"format": "other"}')
        dataset.load(tmp_path)
    with pytest.raises(ValueError, match="poses"):
        omniloop.write_dataset(SCENARIOS / "corner55_velocity_aware.toml", tmp_path / "x",
                               samples=1, poses="everywhere")


def test_a_team_names_the_robot_whose_truth_frames_it_gives():
    from test_team import PAIR

    sim = omniloop.Simulation(omniloop.Scenario.from_toml(PAIR), truth=True)
    sim.reset()
    sim.step({"east": (300.0, 0.0, 0.0), "west": (300.0, 0.0, 0.0)})
    east, west = sim.truth_frames(robot="east"), sim.truth_frames(robot="west")
    assert set(east) == set(west) == {"omni"}
    assert east["omni"]["labels"].shape == (110, 128)
    assert not np.array_equal(east["omni"]["depth_mm"], west["omni"]["depth_mm"])
    robots = [e for e in east["omni"]["legend"] if e["class"] == "robot"]
    assert robots, "each sees the other robot in its legend"
