"""omniloop: a closed-loop testbed for omnidirectional robots with catadioptric vision.

The loop itself, from Python::

    import omniloop

    scenario = omniloop.Scenario.load("scenarios/smoke.toml")
    sim = omniloop.Simulation(scenario)          # Python is the robot's software
    obs = sim.reset()
    while not obs.done:
        obs = sim.step((300.0, 0.0, 0.0))        # vx_mm_s, vy_mm_s, omega_rad_s (body frame)
    print(sim.summary()["wall_contacts"])

- ``Scenario.load(path)``, ``Scenario.from_toml(text)``, ``scenario.with_values({...})``;
  a bad scenario raises ``ScenarioError`` (a ``ValueError``) with ``FILE:LINE:COLUMN: ...``.
- ``run(scenario, seed=None, renderer="cpu", out=None)``: the built-in robot, as
  ``omniloop run`` runs it; ``.summary`` and ``.trajectory``.
- ``Simulation(scenario, seed=None, renderer="cpu", robot="python")``: ``reset``, ``step``,
  ``truth``, ``summary``, ``write``, ``topview``; ``robot="builtin"`` steps the built-in stack;
  ``truth=True`` traces the truth beside each frame (depth, floor distance, labels:
  ``truth_frames()``).
- ``VectorSimulation(scenario, num_envs, ...)``: N runs stepped together in parallel.
- ``sweep(scenario, sets={...}, seeds=..., executor="local"|"ray")``: a grid of runs, on
  this machine or a Ray cluster (``pip install omniloop[ray]``), with ``omniloop sweep``'s
  report; ``resume=True`` goes on from what finished.
- ``write_dataset(scenario, out, samples=100, ...)``: frames of a camera with their truth, as
  ``omniloop dataset`` writes them; ``omniloop.dataset.load(path)`` reads one back.
- ``omniloop.gym``: the Gymnasium environments (``pip install omniloop[gym]``).
- Errors: ``ScenarioError`` (a ``ValueError``) for a scenario; ``SimulationError`` (a
  ``RuntimeError``) for a run that fails as it goes, with ``RobotSoftwareError`` (the robot's
  software), ``RenderError`` (the renderer) and ``RunFinishedError`` (a run stepped after its
  end).
- Typed: ``py.typed`` and the native module's stub; ``omniloop.types`` names the dicts' shapes.

Units are millimetres, seconds and radians. The robot never sees the truth: an
``Observation`` holds what its sensors give; ``Simulation.truth()`` is the simulator's side.
"""

from ._omniloop import (
    FreeSpaceDetector,
    Observation,
    Odometry,
    RenderError,
    RobotSoftwareError,
    RunFinishedError,
    RunResult,
    Scenario,
    ScenarioError,
    Simulation,
    SimulationError,
    VectorSimulation,
    __version__,
    default_scenario,
    run,
)
from .dataset import write_dataset
from .sweeps import SweepResult, sweep, without_timing

__all__ = [
    "FreeSpaceDetector",
    "Observation",
    "Odometry",
    "RenderError",
    "RobotSoftwareError",
    "RunFinishedError",
    "RunResult",
    "Scenario",
    "ScenarioError",
    "Simulation",
    "SimulationError",
    "VectorSimulation",
    "__version__",
    "default_scenario",
    "run",
    "sweep",
    "SweepResult",
    "without_timing",
    "write_dataset",
]
