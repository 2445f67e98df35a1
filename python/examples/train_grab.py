"""Learns the vision-blackout grab (``omniloop/BlackoutGrab-v0``) from the mirror camera with
PPO, evaluates it on held-out placements and writes the curve.

    pip install "./python[train]"
    python python/examples/train_grab.py --observation panorama --seeds 1 2 3 --out runs/grab
    python python/examples/train_grab.py --baseline striker --out runs/grab
    python python/examples/train_grab.py --plot runs/grab          # runs/grab/learning.png

PPO (J. Schulman et al., "Proximal Policy Optimization Algorithms", 2017: the clipped
objective, eq. 7; generalized advantage estimation, eq. 11-12) written on JAX and optax: a
Gaussian policy on what the robot senses (the panorama, the raw image or, for a baseline, the
privileged state, with its odometry and light barrier): on the images two convolutions and a
spatial softmax (Levine et al. 2016), round the azimuth on the panorama, the inputs z-scored by
their running statistics. The value is learnt on the ball's true position (an asymmetric
actor-critic, Pinto et al. 2018): the truth steers the training, as the reward does; the
policy that is evaluated and saved never sees it. Every number that
decides the run is an argument and is written to ``config.json``; the environment's seeds, the
network's initialisation and the sampling all come from ``--seeds``, so a run with ``--steps``
reproduces its weights (``--minutes`` also caps it by the clock, which does not reproduce).

Outputs, per seed under ``OUT/OBSERVATION/seed-S/``: ``curve.csv`` (environment steps, training
wall time without the evaluations, the success rate on the first ``--curve-placements``
held-out placements with ``--curve-limit-s``), ``eval.json`` (the final policy on
``--eval-placements`` held-out placements of 2019 and of 2021 with ``--eval-limit-s``, by default
the rules' minute),
``weights.npz`` and ``config.json``. Held-out placements are the episodes with seeds from
1,000,000,000 on; training episodes have seeds below.
"""

from __future__ import annotations

import argparse
import csv
import json
import math
import sys
import time
from pathlib import Path
from typing import Any, Callable, NamedTuple

import numpy as np

try:
    import jax
    import jax.numpy as jnp
    import optax
except ImportError:  # pragma: no cover - depends on the environment
    sys.exit('train_grab.py needs JAX and optax: pip install "./python[train]"')

import omniloop
import omniloop.grab as grab

HELD_OUT = 1_000_000_000
Params = dict[str, Any]
Array = Any


# ---------------------------------------------------------------- the network


def dense(key: Array, n_in: int, n_out: int, scale: float = math.sqrt(2.0)) -> Params:
    w = jax.nn.initializers.orthogonal(scale)(key, (n_in, n_out))
    return {"w": w, "b": jnp.zeros(n_out)}


class Conv(NamedTuple):
    """A convolution layer: kernel rows and columns, strides, output channels."""

    kh: int
    kw: int
    sh: int
    sw: int
    channels: int


CHANNELS = 16


def layers(kind: str, shape: tuple[int, ...]) -> list[Conv]:
    """The encoder's convolutions on the observation's first entry, before its spatial
    softmax. The panorama's: one layer reads each column whole (a column is an azimuth: the
    same weights at every heading), a second runs round the azimuth (circular). The raw
    image's: one on 8 x 8 tiles and a 3 x 3 one. The state: none."""
    if kind == "panorama":
        return [Conv(shape[0], 1, 1, 1, CHANNELS), Conv(1, 5, 1, 1, CHANNELS)]
    if kind == "image":
        return [Conv(8, 8, 8, 8, CHANNELS), Conv(3, 3, 1, 1, CHANNELS)]
    return []


def features_size(kind: str, shape: tuple[int, ...]) -> int:
    """The state's length, or the spatial softmax's features: each channel's expected
    position (2) and its peak (1)."""
    return int(np.prod(shape)) if kind == "state" else 3 * CHANNELS


def init(key: Array, kind: str, shape: tuple[int, ...], hidden: int = 128) -> Params:
    keys = jax.random.split(key, 8)
    convs, c_in = [], shape[-1] if kind != "state" else 0
    for i, layer in enumerate(layers(kind, shape)):
        fan_in = layer.kh * layer.kw * c_in
        w = jax.random.normal(keys[i], (fan_in, layer.channels)) * math.sqrt(2.0 / fan_in)
        convs.append({"w": w, "b": jnp.zeros(layer.channels)})
        c_in = layer.channels
    n = features_size(kind, shape) + 4  # odometry (3) and the light barrier (1)
    return {
        "convs": convs,
        "trunk1": dense(keys[4], n, hidden),
        "trunk2": dense(keys[5], hidden, hidden),
        "mean": dense(keys[6], hidden, 3, scale=0.01),
        "guess": dense(keys[1], hidden, 2, scale=1.0),
        "critic1": dense(keys[2], 6, hidden),
        "critic2": dense(keys[3], hidden, hidden),
        "value": dense(keys[7], hidden, 1, scale=1.0),
        "log_std": jnp.full(3, -0.5),
        "norm": {"mean": jnp.zeros(norm_shape(kind, shape)), "std": jnp.ones(norm_shape(kind, shape))},
    }


def norm_shape(kind: str, shape: tuple[int, ...]) -> tuple[int, ...]:
    """The input normalization's statistics: per row and channel of the panorama (the same at
    every azimuth), per pixel and channel of the raw image, none for the state."""
    if kind == "panorama":
        return (shape[0], 1, shape[2])
    return tuple(shape) if kind == "image" else (1,)


class RunningNorm:
    """The inputs' running mean and variance (Chan et al.'s parallel update), so that the
    policy sees each row's colours as z-scores: an orange ball on the green floor stands
    out from the first update on (SB3's VecNormalize does the same for vector inputs)."""

    def __init__(self, kind: str, shape: tuple[int, ...]) -> None:
        self.kind, self.shape = kind, norm_shape(kind, shape)
        self.count, self.mean, self.var = 0.0, np.zeros(self.shape), np.ones(self.shape)

    def update(self, frames: np.ndarray) -> dict[str, Array]:
        # One frame in 8 of the rollout: the statistics settle as well, at an eighth the cost.
        x = frames.reshape((-1,) + frames.shape[-3:])[::8].astype(np.float32) / 255.0
        axes = (0, 2) if self.kind == "panorama" else (0,)
        n = x.size / int(np.prod(self.shape))
        mean, var = x.mean(axis=axes, keepdims=True)[0], x.var(axis=axes, keepdims=True)[0]
        total = self.count + n
        delta = mean - self.mean
        self.var = (self.var * self.count + var * n + delta**2 * self.count * n / total) / total
        self.mean, self.count = self.mean + delta * n / total, total
        std = np.maximum(np.sqrt(self.var), 0.02)
        return {"mean": jnp.asarray(self.mean, jnp.float32), "std": jnp.asarray(std, jnp.float32)}


def patches(h: Array, layer: Conv) -> Array:
    """A valid convolution's input patches, ``(B, H', W', kh * kw * C)`` in the kernel's
    ``(row, column, channel)`` order: the convolution is then one matrix product (XLA's CPU
    convolution's gradients are several times slower than its matrix products)."""
    rows = (h.shape[1] - layer.kh) // layer.sh + 1
    cols = (h.shape[2] - layer.kw) // layer.sw + 1
    if (layer.kh, layer.kw) == (layer.sh, layer.sw):  # tiles: a reshape
        b, c = h.shape[0], h.shape[3]
        t = h[:, : rows * layer.kh, : cols * layer.kw].reshape(b, rows, layer.kh, cols, layer.kw, c)
        return t.transpose(0, 1, 3, 2, 4, 5).reshape(b, rows, cols, layer.kh * layer.kw * c)
    taps = [
        h[:, i:i + layer.sh * (rows - 1) + 1:layer.sh, j:j + layer.sw * (cols - 1) + 1:layer.sw, :]
        for i in range(layer.kh) for j in range(layer.kw)
    ]
    return jnp.concatenate(taps, axis=-1)


def spatial_softmax(f: Array, x: Array, y: Array) -> Array:
    """Each channel's expected position under a softmax of its activations and its peak
    (S. Levine, C. Finn, T. Darrell and P. Abbeel, "End-to-End Training of Deep Visuomotor
    Policies", JMLR 17, 2016, section 4.2): ``f`` is ``(B, N, C)`` over ``N`` places at
    ``(x, y)``; on the panorama ``(x, y)`` is the column's ``(cos, sin)`` of its azimuth, so
    the feature is the direction where the channel fires, whatever the heading."""
    p = jax.nn.softmax(f, axis=1)
    return jnp.concatenate([jnp.einsum("bnc,n->bc", p, x), jnp.einsum("bnc,n->bc", p, y), f.max(axis=1)], axis=1)


def encode(params: Params, kind: str, x: Array) -> Array:
    if kind == "state":
        return x.reshape(x.shape[0], -1)
    norm = jax.lax.stop_gradient(params["norm"])
    h = (x.astype(jnp.float32) / 255.0 - norm["mean"]) / norm["std"]
    for p, layer in zip(params["convs"], layers(kind, x.shape[1:])):
        if kind == "panorama" and layer.kw > 1:  # wrap round the azimuth
            left, right = (layer.kw - 1) // 2, layer.kw // 2
            h = jnp.concatenate([h[:, :, -left:], h, h[:, :, :right]], axis=2)
        if layer.kw == 1 and layer.kh == h.shape[1]:  # whole columns: one contraction
            w = p["w"].reshape(layer.kh, h.shape[3], layer.channels)
            h = jax.nn.relu(jnp.einsum("bhwc,hcf->bwf", h, w)[:, None] + p["b"])
        else:
            h = jax.nn.relu(patches(h, layer) @ p["w"] + p["b"])
    b, rows, cols, c = h.shape
    if kind == "panorama":  # one row: the columns' azimuths
        az = math.pi - (jnp.arange(cols) + 0.5) * 2.0 * math.pi / cols
        px, py = jnp.cos(az), jnp.sin(az)
    else:
        gy, gx = jnp.meshgrid(jnp.linspace(-1.0, 1.0, rows), jnp.linspace(-1.0, 1.0, cols), indexing="ij")
        px, py = gx.reshape(-1), gy.reshape(-1)
    return spatial_softmax(h.reshape(b, rows * cols, c), px, py)


def actor(params: Params, kind: str, obs: dict[str, Array]) -> Array:
    """The policy's mean action on what the robot senses: the observation's image (or state),
    odometry and light barrier."""
    return actor_and_guess(params, kind, obs)[0]


def actor_and_guess(params: Params, kind: str, obs: dict[str, Array]) -> tuple[Array, Array]:
    """The mean action and, from the policy's first hidden layer, its guess of where the ball
    is (body frame, m): an auxiliary task (P. Mirowski et al., "Learning to Navigate in
    Complex Environments", ICLR 2017, section 3) that teaches the encoder where the ball is
    from every frame, not only from the rewards; it is trained on the truth and never acted
    on."""
    x = jnp.concatenate(
        [encode(params, kind, obs[kind]), obs["odometry"], obs["ball_in_dribbler"]], axis=1
    )
    x = jnp.tanh(x @ params["trunk1"]["w"] + params["trunk1"]["b"])
    guess = x @ params["guess"]["w"] + params["guess"]["b"]
    x = jnp.tanh(x @ params["trunk2"]["w"] + params["trunk2"]["b"])
    return x @ params["mean"]["w"] + params["mean"]["b"], guess


def critic(params: Params, obs: dict[str, Array]) -> Array:
    """The value, learnt on the ball's true body-frame position beside the odometry and the
    light barrier (L. Pinto et al., "Asymmetric Actor Critic for Image-Based Robot Learning",
    RSS 2018): it steers the training only; the policy never sees the truth."""
    x = jnp.concatenate([obs["critic"], obs["odometry"], obs["ball_in_dribbler"]], axis=1)
    for name in ("critic1", "critic2"):
        x = jnp.tanh(x @ params[name]["w"] + params[name]["b"])
    return (x @ params["value"]["w"] + params["value"]["b"])[:, 0]


def forward(params: Params, kind: str, obs: dict[str, Array]) -> tuple[Array, Array]:
    """The policy's mean action and the value of a batch of observations."""
    return actor(params, kind, obs), critic(params, obs)


def log_prob(params: Params, mean: Array, action: Array) -> Array:
    std = jnp.exp(params["log_std"])
    z = (action - mean) / std
    return jnp.sum(-0.5 * z * z - params["log_std"] - 0.5 * math.log(2.0 * math.pi), axis=-1)


# ---------------------------------------------------------------- PPO


class Config(NamedTuple):
    observation: str
    num_envs: int
    n_steps: int
    epochs: int
    minibatches: int
    lr: float
    gamma: float
    gae_lambda: float
    clip: float
    vf_coef: float
    ent_coef: float
    max_grad_norm: float
    train_limit_s: float
    aux_coef: float


def ppo_loss(params: Params, kind: str, cfg: Config, batch: dict[str, Array]) -> Array:
    mean, guess = actor_and_guess(params, kind, batch["obs"])
    value = critic(params, batch["obs"])
    logp = log_prob(params, mean, batch["action"])
    ratio = jnp.exp(logp - batch["logp"])
    adv = batch["adv"]
    clipped = jnp.clip(ratio, 1.0 - cfg.clip, 1.0 + cfg.clip)
    w = batch["valid"]
    n = jnp.maximum(w.sum(), 1.0)
    policy = -jnp.sum(w * jnp.minimum(ratio * adv, clipped * adv)) / n
    vf = jnp.sum(w * (value - batch["ret"]) ** 2) / n
    entropy = jnp.sum(params["log_std"] + 0.5 * math.log(2.0 * math.pi * math.e))
    aux = jnp.sum(w * jnp.sum((guess - batch["obs"]["critic"]) ** 2, axis=1)) / n
    return policy + cfg.vf_coef * vf - cfg.ent_coef * entropy + cfg.aux_coef * aux


def advantages(cfg: Config, roll: dict[str, np.ndarray], last_value: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """GAE over the rollout. A step that ends its episode bootstraps from the value of the
    observation it returned (the final one) unless the episode terminated; the step after it
    (the vector env's autoreset, no transition) is masked out."""
    values, rewards = roll["value"], roll["reward"]
    term, done = roll["terminated"], roll["done"]
    adv = np.zeros_like(rewards)
    next_adv = np.zeros(cfg.num_envs)
    for t in reversed(range(cfg.n_steps)):
        next_value = values[t + 1] if t + 1 < cfg.n_steps else last_value
        delta = rewards[t] + cfg.gamma * next_value * (1.0 - term[t]) - values[t]
        adv[t] = delta + cfg.gamma * cfg.gae_lambda * (1.0 - done[t]) * next_adv
        adv[t] *= roll["valid"][t]
        next_adv = adv[t]
    return adv, adv + values


class Learner:
    """The policy, its optimizer and PPO's update, jitted once."""

    def __init__(self, cfg: Config, shape: tuple[int, ...], seed: int) -> None:
        self.cfg, kind = cfg, cfg.observation
        self.key = jax.random.PRNGKey(seed)
        self.key, k = jax.random.split(self.key)
        self.params = init(k, kind, shape)
        self.norm = RunningNorm(kind, shape) if kind != "state" else None
        self.opt = optax.chain(optax.clip_by_global_norm(cfg.max_grad_norm), optax.adam(cfg.lr))
        self.opt_state = self.opt.init(self.params)

        def act(params: Params, obs: dict[str, Array], key: Array) -> tuple[Array, ...]:
            mean, value = forward(params, kind, obs)
            action = mean + jnp.exp(params["log_std"]) * jax.random.normal(key, mean.shape)
            return action, log_prob(params, mean, action), value, mean

        def update(params: Params, opt_state: Any, batch: dict[str, Array]) -> tuple[Params, Any]:
            grads = jax.grad(ppo_loss)(params, kind, cfg, batch)
            updates, opt_state = self.opt.update(grads, opt_state, params)
            return optax.apply_updates(params, updates), opt_state

        self._act = jax.jit(act)
        self._mean = jax.jit(lambda params, obs: actor(params, kind, obs))
        self._update = jax.jit(update)

    def act(self, obs: dict[str, np.ndarray]) -> tuple[np.ndarray, ...]:
        self.key, k = jax.random.split(self.key)
        return tuple(np.asarray(v) for v in self._act(self.params, obs, k))

    def mean_action(self, obs: dict[str, np.ndarray]) -> np.ndarray:
        """The policy's action on what the robot senses (no truth: the critic is not used)."""
        return np.asarray(self._mean(self.params, {k: v for k, v in obs.items() if k != "critic"}))

    def learn(self, roll: dict[str, Any], last_value: np.ndarray) -> None:
        cfg = self.cfg
        if self.norm is not None:  # the statistics of what the policy has seen so far
            self.params = {**self.params, "norm": self.norm.update(roll["obs"][cfg.observation])}
        adv, ret = advantages(cfg, roll, last_value)
        valid = roll["valid"].reshape(-1)
        a = adv.reshape(-1)
        live = a[valid > 0]
        a = (a - live.mean()) / (live.std() + 1e-8) if live.size > 1 else a
        flat = {
            "obs": {k: v.reshape((-1,) + v.shape[2:]) for k, v in roll["obs"].items()},
            "action": roll["action"].reshape(-1, 3), "logp": roll["logp"].reshape(-1),
            "adv": a, "ret": ret.reshape(-1), "valid": valid,
        }
        n = cfg.n_steps * cfg.num_envs
        size = n // cfg.minibatches
        rng = np.random.default_rng(int(jax.random.randint(self.key, (), 0, 2**31 - 1)))
        for _ in range(cfg.epochs):
            order = rng.permutation(n)
            for m in range(cfg.minibatches):
                idx = order[m * size:(m + 1) * size]
                batch = jax.tree_util.tree_map(lambda v: v[idx], flat)
                self.params, self.opt_state = self._update(self.params, self.opt_state, batch)


def rollout(env: grab.GrabVectorEnv, learner: Learner, state: dict[str, Any]) -> dict[str, Any]:
    """``n_steps`` steps of every run; ``state`` carries the last observation across calls and
    counts the episodes that ended (and how many with the ball)."""
    cfg = learner.cfg
    keys = ("value", "reward", "terminated", "done", "valid", "logp")
    roll: dict[str, Any] = {k: np.zeros((cfg.n_steps, cfg.num_envs)) for k in keys}
    roll["action"] = np.zeros((cfg.n_steps, cfg.num_envs, 3))
    roll["obs"] = {k: np.zeros((cfg.n_steps,) + v.shape, v.dtype) for k, v in state["obs"].items()}
    roll["obs"]["critic"] = np.zeros((cfg.n_steps, cfg.num_envs, 2), np.float32)
    for t in range(cfg.n_steps):
        obs = {**state["obs"], "critic": state["critic"]}
        action, logp, value, _ = learner.act(obs)
        for k, v in obs.items():
            roll["obs"][k][t] = v
        roll["action"][t], roll["logp"][t], roll["value"][t] = action, logp, value
        roll["valid"][t] = ~state["resetting"]
        state["obs"], reward, term, trunc, info = env.step(np.clip(action, -1.0, 1.0))
        state["critic"] = info["state"]
        done = term | trunc
        roll["reward"][t], roll["terminated"][t], roll["done"][t] = reward, term, done
        state["episodes"] += int(done.sum())
        state["successes"] += int((done & info["success"]).sum())
        state["resetting"] = done
    last_value = np.asarray(learner.act({**state["obs"], "critic": state["critic"]})[2])
    learner.learn(roll, last_value)
    return roll


# ---------------------------------------------------------------- evaluation


def evaluate(
    policy: Callable[[dict[str, np.ndarray]], np.ndarray], observation: str, placements: str,
    count: int, limit_s: float, num_envs: int = 16, stack: tuple[int, int] = (1, 1),
) -> dict[str, Any]:
    """The policy on ``count`` held-out placements (seeds from ``HELD_OUT``): success rate and
    each placement's outcome and time."""
    # Run k plays placements k, k + n, k + 2n, ... (the vector env's autoreset moves each run's
    # seed on by n): no run waits for the slowest of a batch.
    n = min(num_envs, count)
    env = grab.GrabVectorEnv(
        n, observation=observation, placements=placements, time_limit_s=limit_s,
        stack=stack[0], stack_every=stack[1],
    )
    outcomes: dict[int, tuple[bool, float]] = {}
    obs, _ = env.reset(seed=HELD_OUT)
    while len(outcomes) < count:
        obs, _, term, trunc, info = env.step(policy(obs))
        for i in np.flatnonzero(term | trunc):
            seed = int(info["seed"][i])
            if seed < HELD_OUT + count:
                outcomes[seed] = (bool(info["success"][i]), float(info["time_s"][i]))
    ok = [s for s, _ in outcomes.values()]
    times = sorted(t for s, t in outcomes.values() if s)
    return {
        "placements": placements, "count": len(ok), "limit_s": limit_s,
        "success_rate": float(np.mean(ok)),
        "median_time_s": times[len(times) // 2] if times else None,
        "outcomes": {str(k): v for k, v in sorted(outcomes.items())},
    }


def striker(placements: str, count: int, limit_s: float) -> dict[str, Any]:
    """The built-in striker (its hand-written ball detector on the mirror image) on the same
    held-out placements."""
    task = grab.GrabTask(grab.GrabConfig(observation="state", placements=placements, time_limit_s=limit_s))
    outcomes = {}
    for k in range(count):
        seed = HELD_OUT + k
        sim = omniloop.Simulation(task.scenario(seed), seed=seed, robot="builtin")
        while not sim.done and not sim.truth()["ball_in_dribbler"]:
            sim.step()
        truth = sim.truth()
        outcomes[str(seed)] = (bool(truth["ball_in_dribbler"]), float(truth["t_s"]))
    ok = [s for s, _ in outcomes.values()]
    times = sorted(t for s, t in outcomes.values() if s)
    return {
        "placements": placements, "count": count, "limit_s": limit_s,
        "success_rate": float(np.mean(ok)),
        "median_time_s": times[len(times) // 2] if times else None, "outcomes": outcomes,
    }


# ---------------------------------------------------------------- the command


def train(args: argparse.Namespace, seed: int, out: Path) -> dict[str, Any]:
    """One seed's run: trains, writes the curve as it goes, evaluates, saves the weights."""
    cfg = Config(
        args.observation, args.envs, args.n_steps, args.epochs, args.minibatches, args.lr,
        args.gamma, args.gae_lambda, args.clip, args.vf_coef, args.ent_coef, args.max_grad_norm,
        args.train_limit_s, args.aux_coef if args.observation != "state" else 0.0,
    )
    out.mkdir(parents=True, exist_ok=True)
    (out / "config.json").write_text(json.dumps({**vars(args), "seed": seed, "out": str(args.out)}, indent=1))
    stack = (args.stack, args.stack_every)
    env = grab.GrabVectorEnv(
        cfg.num_envs, observation=cfg.observation, time_limit_s=cfg.train_limit_s,
        stack=stack[0], stack_every=stack[1],
    )
    obs, info = env.reset(seed=seed * 10_000_000)
    shape = tuple(env.task.observation_space[cfg.observation].shape or ())
    learner = Learner(cfg, shape, seed)
    state: dict[str, Any] = {
        "obs": obs, "critic": info["state"], "resetting": np.zeros(cfg.num_envs, dtype=bool),
        "episodes": 0, "successes": 0,
    }
    steps, wall, next_eval = 0, 0.0, 0
    with open(out / "curve.csv", "w", newline="") as f:
        rows = csv.writer(f)
        rows.writerow(["env_steps", "train_wall_s", "success_rate", "train_episodes", "train_success_rate"])
        while True:
            if steps >= next_eval:
                rate = evaluate(
                    learner.mean_action, cfg.observation, "2019", args.curve_placements,
                    args.curve_limit_s, stack=stack,
                )
                ep = state["episodes"]
                rows.writerow([steps, round(wall, 2), rate["success_rate"], ep, state["successes"] / max(ep, 1)])
                f.flush()
                print(f"seed {seed}: {steps} steps, {wall:.0f} s: held-out success "
                      f"{rate['success_rate']:.0%}", file=sys.stderr)
                state["episodes"] = state["successes"] = 0
                next_eval += args.eval_every
            if steps >= args.steps or wall >= 60.0 * args.minutes:
                break
            start = time.perf_counter()
            rollout(env, learner, state)
            wall += time.perf_counter() - start
            steps += cfg.n_steps * cfg.num_envs
    weights = {
        "/".join(str(p) for p in path): np.asarray(v)
        for path, v in jax.tree_util.tree_flatten_with_path(learner.params)[0]
    }
    np.savez(out / "weights.npz", **weights)  # type: ignore[arg-type]
    result = {
        "seed": seed, "env_steps": steps, "train_wall_s": wall,
        "eval": {
            p: evaluate(learner.mean_action, cfg.observation, p, args.eval_placements, args.eval_limit_s, stack=stack)
            for p in ("2019", "2021")
        },
    }
    (out / "eval.json").write_text(json.dumps(result, indent=1))
    return result


def random_policy(seed: int) -> Callable[[dict[str, np.ndarray]], np.ndarray]:
    rng = np.random.default_rng(seed)
    return lambda obs: rng.uniform(-1.0, 1.0, (len(obs["odometry"]), 3))


def baseline(args: argparse.Namespace) -> None:
    out = args.out / args.baseline
    out.mkdir(parents=True, exist_ok=True)
    result = {}
    for p in ("2019", "2021"):
        if args.baseline == "striker":
            result[p] = striker(p, args.eval_placements, args.eval_limit_s)
        else:
            result[p] = evaluate(random_policy(1), "state", p, args.eval_placements, args.eval_limit_s)
        print(f"{args.baseline}, {p} placements: {result[p]['success_rate']:.0%}", file=sys.stderr)
    (out / "eval.json").write_text(json.dumps(result, indent=1))


def curves(root: Path) -> dict[str, list[np.ndarray]]:
    """Each observation's curves under ``root``: one array (steps, wall s, rate) a seed."""
    found: dict[str, list[np.ndarray]] = {}
    for kind in grab.OBSERVATIONS:
        for path in sorted((root / kind).glob("seed-*/curve.csv")):
            rows = list(csv.DictReader(path.open()))
            cols = [[float(r[k]) for k in ("env_steps", "train_wall_s", "success_rate")] for r in rows]
            found.setdefault(kind, []).append(np.array(cols))
    return found


def finals_of(kind_dir: Path) -> np.ndarray:
    """Each seed's final evaluation under ``kind_dir``: (steps, wall s, 2019 success rate)."""
    rows = []
    for path in sorted(kind_dir.glob("seed-*/eval.json")):
        e = json.loads(path.read_text())
        rows.append([e["env_steps"], e["train_wall_s"], e["eval"]["2019"]["success_rate"]])
    return np.array(rows).reshape(-1, 3)


def plot(root: Path) -> Path:
    """``root/learning.png``: held-out success against environment steps and against training
    wall time, the mean of the seeds and their spread (min to max), each seed's final policy
    (circles), beside the baselines."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 2, figsize=(11, 4), sharey=True)
    for kind, runs in curves(root).items():
        n = min(len(r) for r in runs)
        rates = np.stack([r[:n, 2] for r in runs])
        finals = finals_of(root / kind)
        for ax, col in zip(axes, (0, 1)):
            x = np.mean([r[:n, col] for r in runs], axis=0)
            line = ax.plot(x, rates.mean(axis=0), label=f"PPO on {kind} ({len(runs)} seeds)")
            color = line[0].get_color()
            ax.fill_between(x, rates.min(axis=0), rates.max(axis=0), alpha=0.2, color=color)
            if len(finals):
                ax.scatter(finals[:, col], finals[:, 2], marker="o", facecolors="none", edgecolors=color)
    for name, style in (("striker", "--"), ("random", ":")):
        path = root / name / "eval.json"
        if path.is_file():
            rate = json.loads(path.read_text())["2019"]["success_rate"]
            for ax in axes:
                ax.axhline(rate, linestyle=style, color="k", label=f"{name} ({rate:.0%}, 60 s)")
    axes[0].scatter([], [], marker="o", facecolors="none", edgecolors="k",
                    label="a seed's final policy (100 placements, 60 s)")
    axes[0].set_xlabel("environment steps")
    axes[1].axvline(1200.0, color="grey", linewidth=0.8)
    axes[1].text(1190.0, 0.02, "20 min", rotation=90, ha="right", va="bottom", color="grey")
    axes[1].set_xlabel("training wall time on this machine, s")
    axes[0].set_ylabel("held-out success (touch with the dribbler)")
    axes[0].legend(loc="lower right", fontsize=8)
    fig.suptitle("omniloop/BlackoutGrab-v0, 2019 placements "
                 "(lines: 32 held-out placements, 10 s; band: the seeds' spread)")
    fig.tight_layout()
    out = root / "learning.png"
    fig.savefig(out, dpi=110)
    return out


def parser() -> argparse.ArgumentParser:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    add = ap.add_argument
    add("--observation", choices=grab.OBSERVATIONS, default="panorama")
    add("--seeds", type=int, nargs="+", default=[1])
    add("--out", type=Path, default=Path("runs/grab"))
    add("--steps", type=int, default=450_000, help="environment steps a seed")
    add("--minutes", type=float, default=20.0, help="training wall-time cap a seed")
    add("--envs", type=int, default=16)
    add("--n-steps", type=int, default=64, help="steps a run between updates")
    add("--epochs", type=int, default=4)
    add("--minibatches", type=int, default=4)
    add("--lr", type=float, default=3e-4)
    add("--gamma", type=float, default=0.99)
    add("--gae-lambda", type=float, default=0.95)
    add("--clip", type=float, default=0.2)
    add("--vf-coef", type=float, default=0.5)
    add("--ent-coef", type=float, default=0.0)
    add("--max-grad-norm", type=float, default=0.5)
    add("--train-limit-s", type=float, default=5.0, help="training episodes' time limit")
    add("--aux-coef", type=float, default=1.0,
        help="weight of the auxiliary loss (the ball's place guessed from the image)")
    add("--stack", type=int, default=4, help="images or strips the policy sees (a memory)")
    add("--stack-every", type=int, default=3, help="steps between them")
    add("--eval-every", type=int, default=50_000, help="environment steps between curve points")
    add("--curve-placements", type=int, default=32)
    add("--curve-limit-s", type=float, default=10.0)
    add("--eval-placements", type=int, default=100)
    add("--eval-limit-s", type=float, default=60.0,
        help="the final evaluation's time limit (the rules' minute)")
    add("--baseline", choices=("random", "striker"), help="evaluate a baseline instead")
    add("--plot", type=Path, metavar="DIR", help="draw DIR/learning.png from DIR's runs")
    return ap


def main() -> int:
    args = parser().parse_args()
    if args.plot is not None:
        print(plot(args.plot))
        return 0
    if args.baseline is not None:
        baseline(args)
        return 0
    rates = []
    for seed in args.seeds:
        r = train(args, seed, args.out / args.observation / f"seed-{seed}")
        rates.append(r["eval"]["2019"]["success_rate"])
        print(f"seed {seed}: {r['eval']['2019']['success_rate']:.0%} of 2019 placements, "
              f"{r['eval']['2021']['success_rate']:.0%} of 2021", file=sys.stderr)
    print(f"{args.observation}: {np.mean(rates):.0%} mean over {len(rates)} seed(s), "
          f"spread {np.min(rates):.0%}-{np.max(rates):.0%}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
