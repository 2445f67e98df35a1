"""Your own striker: the vision-blackout challenge's first stage (grab a stationary ball) played
from the omnidirectional image alone. The robot finds the orange ball in its mirror image,
turns to it, drives at it (slowing as its image nears the body's blind zone) with the dribbler
spinning, and stops once the dribbler's light barrier holds the ball.

    python python/examples/grab_ball.py [SEED]
"""

import math
import sys

import numpy as np

import omniloop
from omniloop.types import Dribble

scenario = omniloop.Scenario.load("scenarios/blackout_stage1.toml")
sim = omniloop.Simulation(scenario)  # this script is the robot's software
obs = sim.reset(seed=int(sys.argv[1]) if len(sys.argv) > 1 else None)


def find_ball(img: np.ndarray) -> tuple[float, float] | None:
    """The ball's bearing (rad, counter-clockwise from forward) and image radius (px) in a
    mirror image: the centroid of its orange pixels about the image centre (forward is the
    image's right, left its top), or None when none shows."""
    r, g, b = (img[..., k].astype(np.float32) for k in range(3))
    ratio = g / np.maximum(r, 1.0)
    orange = (r >= 60) & (ratio > 0.22) & (ratio < 0.68) & (b < 0.4 * r)
    rows, cols = np.nonzero(orange)
    if len(rows) == 0:
        return None
    h, w = orange.shape
    x = cols + 0.5 - w / 2.0
    y = h / 2.0 - (rows + 0.5)
    return math.atan2(y.sum(), x.sum()), float(np.hypot(x, y).min())


last_bearing, held_for = 0.0, 0
while not obs.done and held_for < 15:
    img = obs.frames["omni"]
    seen = find_ball(img)
    dribble: Dribble = {"dribbler_rpm": 5000.0}
    if obs.ball_in_dribbler:  # the light barrier: the ball is ours, stop and hold it
        held_for += 1
        obs = sim.step((0.0, 0.0, 0.0), [dribble])
        continue
    held_for = 0
    if seen is None:  # in the blind zone by the body, or out of view: creep on or turn
        near = abs(last_bearing) < 0.3
        command = (250.0, 0.0, 0.0) if near else (0.0, 0.0, 1.5 * math.copysign(1.0, last_bearing))
    else:
        bearing, radius_px = seen
        last_bearing = bearing
        turn = max(-3.0, min(3.0, 4.0 * bearing))
        speed = 0.0 if abs(bearing) > 0.4 else min(1200.0, 25.0 * max(radius_px - 20.0, 10.0))
        command = (speed, 0.0, turn)
    obs = sim.step(command, [dribble])

truth = sim.truth()
print(f"held the ball: {truth['ball_in_dribbler']} after {obs.t_s:.1f} s")
