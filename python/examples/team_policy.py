"""Six robots driven by one Python policy, each on its own camera (PettingZoo).

The six robots of ``scenarios/swarm_swap.toml`` swap to their antipodes through the centre. Every
robot is an agent; the same small policy drives each from its own observation: its camera image
and where its dead reckoning puts its goal. It reads the mirror image as the corner paper does
(a floor point at azimuth phi images at image angle phi, farther out the farther away): in the
ring of the image where the floor lies 0.3 to 0.8 m away, a sector with little floor colour
holds something, most likely another robot. The policy heads for its goal, and when the way
there holds something it takes the first sector to the right that is clear, at a slower speed:
the rule of the road, everybody keeping right.

    pip install "./python[pettingzoo]"
    python python/examples/team_policy.py

It prints how each robot did (arrival, contacts) from the truth, which the policy never sees.
"""

import math
import sys
from pathlib import Path
from typing import Dict

import numpy as np

from omniloop.pettingzoo import parallel_env

SCENARIO = Path(__file__).resolve().parents[2] / "scenarios" / "swarm_swap.toml"
SECTORS = 24
RING_PX = (58.0, 88.0)  # image radii where E1's mirror sees the floor 0.3 to 0.8 m away


def blocked_sectors(image: np.ndarray) -> np.ndarray:
    """For each of SECTORS azimuth sectors, whether the ring holds less than 70% floor."""
    h, w, _ = image.shape
    v, u = np.mgrid[0:h, 0:w]
    dx, dy = u - (w - 1) / 2.0, (h - 1) / 2.0 - v
    r = np.hypot(dx, dy)
    ring = (r >= RING_PX[0]) & (r < RING_PX[1])
    sector = ((np.arctan2(dy, dx) % (2 * math.pi)) / (2 * math.pi) * SECTORS).astype(int) % SECTORS
    rgb = image.astype(np.int16)
    floor = (rgb[..., 1] > rgb[..., 0] + 30) & (rgb[..., 1] > rgb[..., 2] + 30)
    total = np.bincount(sector[ring], minlength=SECTORS)
    green = np.bincount(sector[ring & floor], minlength=SECTORS)
    return green < 0.7 * np.maximum(total, 1)


def policy(observation: Dict[str, np.ndarray]) -> np.ndarray:
    """A body-frame command (vx, vy, omega) toward the goal, keeping right of what is ahead."""
    gx, gy = (float(c) for c in observation["goal"])
    distance = math.hypot(gx, gy)
    speed = min(350.0, 1.5 * distance)
    if distance < 1.0:
        return np.zeros(3)
    blocked = blocked_sectors(observation["omni"])
    width = 2 * math.pi / SECTORS
    goal_sector = int((math.atan2(gy, gx) % (2 * math.pi)) / width) % SECTORS
    heading = math.atan2(gy, gx)
    ahead = [blocked[(goal_sector + k) % SECTORS] for k in (-1, 0, 1)]
    if distance > 350.0 and any(ahead):
        # The first clear sector to the right (clockwise), slower.
        for k in range(1, SECTORS // 2):
            s = (goal_sector - k) % SECTORS
            if not blocked[s] and not blocked[(s + 1) % SECTORS]:
                heading = (s + 0.5) * width
                speed *= 0.5
                break
        else:
            return np.zeros(3)
    return np.array([speed * math.cos(heading), speed * math.sin(heading), 0.0])


def main() -> int:
    env = parallel_env(SCENARIO)
    observations, infos = env.reset(seed=1)
    steps = 0
    while env.agents:
        actions = {a: policy(observations[a]) for a in env.agents}
        observations, rewards, terminations, truncations, infos = env.step(actions)
        steps += 1
    summary = env.sim.summary()
    for row in summary["robots"]:
        arrived = f"arrived at {row['time_to_goal_s']:.1f} s" if row["reached_goal"] else "did not arrive"
        print(f"{row['name']}: {arrived}, contacts {row['contacts']}")
    team = summary["team"]
    print(
        f"{team['arrived']} of {team['robots']} arrived in {steps} steps; contacts "
        f"{summary['wall_contacts']} (between robots {team['robot_contacts']}); least clearance "
        f"between robots {team['min_robot_clearance_mm']:.0f} mm"
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
