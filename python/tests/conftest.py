"""Shared paths and scenarios of the Python tests (run from anywhere: `pytest python/tests`)."""

import os
import random
from pathlib import Path

import pytest

import omniloop

ROOT = Path(__file__).resolve().parents[2]
SCENARIOS = ROOT / "scenarios"


def ros_domain_id() -> int:
    """A ROS 2 domain (1-100) for this test process's nodes.

    Drawn from the test run's process id, so that two runs on one machine seldom meet, and
    offset by the pytest-xdist worker's index (`pytest -n`, as scripts/test.sh runs), so that
    two workers of one run never share a domain: each worker's nodes would see the other's
    topics.
    """
    worker = os.environ.get("PYTEST_XDIST_WORKER")  # gw0, gw1, ... under pytest -n
    run = os.getppid() if worker else os.getpid()
    index = int(worker[2:]) if worker else 0
    return 1 + (random.Random(run).randrange(100) + index) % 100


@pytest.fixture(scope="session")
def smoke() -> omniloop.Scenario:
    """Across the field to a goal past two cubes and a moving robot; no camera."""
    return omniloop.Scenario.load(SCENARIOS / "smoke.toml")


@pytest.fixture(scope="session")
def corner() -> omniloop.Scenario:
    """E1's 55-degree corner, velocity-aware: a hyperbolic mirror camera at 256x220."""
    return omniloop.Scenario.load(SCENARIOS / "corner55_velocity_aware.toml")


@pytest.fixture(scope="session")
def pinhole() -> omniloop.Scenario:
    """A forward pinhole camera on a pan unit, one second long."""
    return omniloop.Scenario.load(SCENARIOS / "render_pinhole.toml")


def goal_in_body(obs, goal):
    """Where `goal` (world frame, mm) lies in the body frame by the observation's dead
    reckoning."""
    import math

    x, y, theta = obs.odometry_pose
    dx, dy = goal[0] - x, goal[1] - y
    c, s = math.cos(theta), math.sin(theta)
    return (c * dx + s * dy, -s * dx + c * dy)


def to_goal(goal_body_mm, speed_mm_s: float = 400.0):
    """A proportional step toward a goal given in the body frame: (vx, vy, omega)."""
    gx, gy = float(goal_body_mm[0]), float(goal_body_mm[1])
    d = max((gx * gx + gy * gy) ** 0.5, 1e-9)
    v = min(speed_mm_s, 2.0 * d)
    return (v * gx / d, v * gy / d, 0.0)


def pytest_configure(config: pytest.Config) -> None:
    config.addinivalue_line(
        "markers", "long: a test of tens of seconds, started first (see below)"
    )


def pytest_collection_modifyitems(items: list) -> None:
    """The tests marked `long` first, in their order, then the rest in theirs: pytest-xdist
    (`pytest -n`, as scripts/test.sh runs) hands tests out in this order, so that the long ones
    start early and no worker is left running one alone at the end."""
    items.sort(key=lambda item: item.get_closest_marker("long") is None)
