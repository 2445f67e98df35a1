"""The exceptions omniloop raises: `ScenarioError` (a `ValueError`) for a scenario, the
`SimulationError` family (`RuntimeError`s) for a run that fails as it goes."""

import numpy as np
import pytest

import omniloop


def test_the_exceptions_are_exported_with_their_documented_bases():
    assert issubclass(omniloop.ScenarioError, ValueError)
    assert issubclass(omniloop.SimulationError, RuntimeError)
    for kind in (omniloop.RobotSoftwareError, omniloop.RenderError, omniloop.RunFinishedError):
        assert issubclass(kind, omniloop.SimulationError)
    assert not issubclass(omniloop.SimulationError, ValueError)
    assert omniloop.SimulationError.__module__ == "omniloop"


def test_stepping_a_finished_simulation_raises_run_finished_error(pinhole):
    sim = omniloop.Simulation(pinhole)
    obs = sim.reset()
    while not obs.done:
        obs = sim.step((0.0, 0.0, 0.0))
    with pytest.raises(omniloop.RunFinishedError, match="the run is over") as e:
        sim.step((0.0, 0.0, 0.0))
    assert isinstance(e.value, omniloop.SimulationError) and isinstance(e.value, RuntimeError)
    assert not sim.reset().done, "reset() runs again"


def test_stepping_a_finished_run_of_a_vector_raises_run_finished_error(pinhole):
    vec = omniloop.VectorSimulation(pinhole, 2)
    while not all(vec.done):
        vec.step([(0.0, 0.0, 0.0)] * 2)
    with pytest.raises(omniloop.RunFinishedError, match="run 0 is over"):
        vec.step([(0.0, 0.0, 0.0)] * 2)
    assert len(vec.step([(0.0, 0.0, 0.0)] * 2, active=[False, False])) == 2, "idle runs wait"


def test_the_free_space_stage_failing_on_a_frame_raises_robot_software_error(corner):
    detector = omniloop.Simulation(corner).free_space_detector()
    with pytest.raises(omniloop.RobotSoftwareError, match="free space"):
        detector.detect(np.zeros((16, 16, 3), dtype=np.uint8))


def test_a_frame_of_any_memory_layout_is_read_and_one_not_rgb_raises_value_error(corner):
    sim = omniloop.Simulation(corner)
    frame = sim.reset().frames["omni"]
    flipped = frame[::-1, ::-1]  # a view with negative strides: copied into rows by the binding
    assert not flipped.flags["C_CONTIGUOUS"]
    a = sim.free_space_detector().detect(flipped)
    b = sim.free_space_detector().detect(np.ascontiguousarray(flipped))
    assert a.keys() == b.keys()
    assert all(np.array_equal(a[k], b[k]) for k in a)
    # The flipped frame is another image: the ranges differ from the frame's own.
    c = sim.free_space_detector().detect(frame)
    assert not np.array_equal(a["free_mm"], c["free_mm"])
    with pytest.raises(ValueError, match=r"H x W x 3 uint8 array \(RGB\), got shape \[16, 16, 4\]"):
        sim.free_space_detector().detect(np.zeros((16, 16, 4), dtype=np.uint8))
