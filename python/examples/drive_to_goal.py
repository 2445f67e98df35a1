import math, omniloop

scenario = omniloop.Scenario.load("scenarios/smoke.toml")
goal = scenario.robot["goal"]
assert goal is not None                        # smoke.toml has one
gx, gy = goal["x_mm"], goal["y_mm"]
sim = omniloop.Simulation(scenario)            # your Python code is the robot's software
obs = sim.reset(seed=1)
while not obs.done:
    x, y, th = obs.odometry_pose               # dead reckoning: the robot's own belief
    dx, dy = gx - x, gy - y
    k = min(400.0, 2 * math.hypot(dx, dy)) / max(math.hypot(dx, dy), 1e-9)
    c, s = math.cos(th), math.sin(th)          # world frame -> body frame (x forward)
    obs = sim.step((k * (c * dx + s * dy), k * (c * dy - s * dx), 0.0))
print("reached goal:", sim.truth()["reached_goal"], "contacts:", sim.truth()["contacts"])
