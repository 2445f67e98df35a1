"""Six against six over the Small-Size League's ports: a scripted match on ``omniloop ssl``.

Each team's robot nearest the ball plays it: it drives behind the ball on the line to the
opponent's goal (aiming at the part of the goal mouth its opponents leave most open), then
forward with its kicker armed at 5 m/s. The other five hold places of a formation that follows
the ball, driven by field-frame velocity commands from a proportional controller saturated at
2.5 m/s. Positions come from vision's detection frames, never from the simulator's truth; the
score comes from the referee's packets, and after a goal the ball goes back to the centre spot
(so too after it lay still for ten seconds). Blue defends the goal at -x.

Against a simulator already running in lockstep (its default ports, 10300-10302, and the
referee's packets on their multicast group)::

    omniloop ssl scenarios/ssl_match.toml --lockstep --no-cameras
    python python/examples/ssl_match.py

or starting one itself (``--serve``; the binary as ``omniloop.ssl.binary_path`` finds it)::

    python python/examples/ssl_match.py --serve

``--real-time`` plays at the simulator's own pace (it must then run without ``--lockstep``),
reading vision's packets; ``--duration`` sets the simulated seconds (60), ``--goals N`` ends
the match after N goals. It prints the final score, when each goal fell and how many errors
the simulator answered (``--json``: as one JSON line).
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import time
from pathlib import Path
from typing import Any, Dict, List, Optional, Sequence, Tuple

from omniloop import ssl

SCENARIO = Path(__file__).resolve().parents[2] / "scenarios" / "ssl_match.toml"
PERIOD_S = 0.01  # the scenario's control period
HALF_LENGTH_M = 4.5
HALF_WIDTH_M = 3.0
MAX_SPEED_M_S = 2.5
GAIN_PER_S = 2.0
KICK_M_S = 5.0
STALL_S = 10.0
KICKOFF_S = 5.0
OUT_S = 1.0

Vec = Tuple[float, float]


def clamp(v: float, lo: float, hi: float) -> float:
    return max(lo, min(hi, v))


def wrap(a: float) -> float:
    """An angle in [-pi, pi)."""
    return (a + math.pi) % (2.0 * math.pi) - math.pi


def toward(robot: Vec, place: Vec, max_speed: float = MAX_SPEED_M_S) -> Vec:
    """A field-frame velocity toward ``place``: proportional, saturated at ``max_speed``."""
    vx, vy = GAIN_PER_S * (place[0] - robot[0]), GAIN_PER_S * (place[1] - robot[1])
    speed = math.hypot(vx, vy)
    if speed > max_speed:
        vx, vy = vx * max_speed / speed, vy * max_speed / speed
    return (vx, vy)


def turn(heading: float, wanted: float) -> float:
    """An angular velocity toward ``wanted``, rad/s."""
    return clamp(4.0 * wrap(wanted - heading), -4.0, 4.0)


class TeamAi:
    """One team's play: ``sign`` is +1 for blue (attacking +x), -1 for yellow."""

    def __init__(self, team: ssl.Team) -> None:
        self.team = team
        self.sign = 1.0 if team == ssl.Team.BLUE else -1.0
        self.attacker: Optional[int] = None

    def formation(self, ball: Vec) -> Dict[int, Vec]:
        """Where each robot stands when it does not play the ball, m (robot 0 keeps goal)."""
        s, bx, by = self.sign, ball[0], ball[1]
        own_goal = -s * HALF_LENGTH_M
        # The field robots shift with the ball, staying on their side of it.
        push = clamp(bx * s, -2.5, 2.5)
        return {
            0: (own_goal + s * 0.25, clamp(by * 0.4, -0.35, 0.35)),
            1: (s * (-3.0 + 0.3 * push), clamp(by * 0.5 + 0.9, -2.6, 2.6)),
            2: (s * (-3.0 + 0.3 * push), clamp(by * 0.5 - 0.9, -2.6, 2.6)),
            3: (s * (-1.8 + 0.5 * push), clamp(by * 0.6, -2.6, 2.6)),
            4: (s * (-0.6 + 0.6 * push), 1.9),
            5: (s * (-0.6 + 0.6 * push), -1.9),
        }

    def choose_attacker(self, ours: Dict[int, Tuple[float, float, float]], ball: Vec) -> int:
        """The robot nearest the ball, keeping the one playing unless another is clearly
        nearer."""
        dist = {i: math.hypot(r[0] - ball[0], r[1] - ball[1]) for i, r in ours.items()}
        best = min(dist, key=lambda i: dist[i])
        if self.attacker in dist and dist[self.attacker] < dist[best] + 0.3:
            return self.attacker
        self.attacker = best
        return best

    def aim(self, ball: Vec, theirs: Sequence[Vec]) -> Vec:
        """The point of the opponent's goal mouth farthest from their robots' shadows."""
        gx = self.sign * HALF_LENGTH_M

        def clearance(y: float) -> float:
            tx, ty = gx - ball[0], y - ball[1]
            length = math.hypot(tx, ty) or 1.0
            worst = math.inf
            for rx, ry in theirs:
                along = ((rx - ball[0]) * tx + (ry - ball[1]) * ty) / length
                if 0.0 < along < length:
                    worst = min(worst, abs((rx - ball[0]) * ty - (ry - ball[1]) * tx) / length)
            return worst

        return (gx, max((-0.32, 0.0, 0.32), key=clearance))

    def play(self, robot: Tuple[float, float, float], ball: Vec, target: Vec) -> Any:
        """The attacker's command: around and behind the ball, then through it, kicking."""
        x, y, heading = robot
        dx, dy = target[0] - ball[0], target[1] - ball[1]
        n = math.hypot(dx, dy) or 1.0
        dx, dy = dx / n, dy / n
        along = (x - ball[0]) * dx + (y - ball[1]) * dy  # < 0: behind the ball
        side = -(x - ball[0]) * dy + (y - ball[1]) * dx
        want = math.atan2(dy, dx)
        if along < -0.09 and abs(side) < 0.04 and abs(wrap(want - heading)) < 0.12:
            # Lined up: through the ball along the line, holding it.
            vx, vy = 1.5 * dx + 4.0 * side * dy, 1.5 * dy - 4.0 * side * dx
            return ssl.global_velocity(0, vx, vy, turn(heading, want), kick_speed=KICK_M_S)
        if along > -0.09:
            # Beside or ahead of it: round it on the side the robot is on.
            s = 1.0 if side >= 0.0 else -1.0
            place = (ball[0] - 0.3 * dx - 0.35 * s * dy, ball[1] - 0.3 * dy + 0.35 * s * dx)
        else:
            place = (ball[0] - 0.2 * dx, ball[1] - 0.2 * dy)
        vx, vy = toward((x, y), place)
        return ssl.global_velocity(0, vx, vy, turn(heading, want))

    def commands(self, seen: ssl.VisionState, kickoff: Optional[ssl.Team] = None) -> List[Any]:
        """This team's commands from what vision saw. During the other team's ``kickoff``
        every robot keeps to its own half, outside the centre circle."""
        ours = {
            i: (r.x_mm / 1000.0, r.y_mm / 1000.0, r.orientation_rad)
            for (t, i), r in seen.robots.items()
            if t == self.team
        }
        theirs = [
            (r.x_mm / 1000.0, r.y_mm / 1000.0)
            for (t, _), r in seen.robots.items()
            if t != self.team
        ]
        if seen.ball is None or not ours:
            return [ssl.global_velocity(i, 0.0, 0.0) for i in range(6)]
        ball = (seen.ball[0] / 1000.0, seen.ball[1] / 1000.0)
        waiting = kickoff is not None and kickoff != self.team
        attacker = None if waiting else self.choose_attacker(ours, ball)
        places = self.formation(ball)
        if waiting:
            places = {i: (self.sign * min(self.sign * x, -0.7), y) for i, (x, y) in places.items()}
        out = []
        for i, (x, y, heading) in sorted(ours.items()):
            if i == attacker:
                c = self.play((x, y, heading), ball, self.aim(ball, theirs))
                c.id = i
            else:
                vx, vy = toward((x, y), places.get(i, (x, y)))
                c = ssl.global_velocity(i, vx, vy, turn(heading, 0.0 if self.sign > 0 else math.pi))
            out.append(c)
        return out


class Match:
    """The game's bookkeeping: errors answered, goals, the ball's last movement."""

    def __init__(self, client: ssl.SslClient) -> None:
        self.client = client
        self.errors: List[str] = []
        self.goals: List[Tuple[float, str]] = []
        self.t_s = 0.0
        """How long it was played, s."""
        self.score = (0, 0)
        self.stall_restarts = 0
        self.throw_ins = 0
        self.kickoff: Optional[ssl.Team] = ssl.Team.BLUE
        """The team kicking off now (none once the ball is in play)."""
        self._last_kickoff = ssl.Team.BLUE
        self._kickoff_since = 0.0
        self._spot_seen = False
        self._still_since: Optional[float] = None
        self._ball_at: Optional[Vec] = None
        self._out_since: Optional[float] = None

    def count(self, response: Any) -> None:
        """Takes the errors of an answer."""
        self.errors.extend(ssl.error_codes(response))

    def referee(self, packet: Any, t_s: float) -> None:
        """Takes the referee's latest packet: a new goal puts the ball back on the spot."""
        if packet is None:
            return
        score = (int(packet.blue.score), int(packet.yellow.score))
        if score != self.score:
            for _ in range(score[0] - self.score[0]):
                self.goals.append((t_s, "blue"))
            for _ in range(score[1] - self.score[1]):
                self.goals.append((t_s, "yellow"))
            # The team that conceded kicks off.
            conceded = ssl.Team.YELLOW if score[0] > self.score[0] else ssl.Team.BLUE
            self.score = score
            self.restart(t_s, conceded)

    def watch_ball(self, seen: ssl.VisionState, t_s: float) -> None:
        """Ends a kick-off once the ball moved (or after KICKOFF_S); a ball lying still for
        STALL_S goes back to the centre spot, the kick-off to the other team."""
        if seen.ball is None:
            return
        b = (seen.ball[0] / 1000.0, seen.ball[1] / 1000.0)
        if self.kickoff is not None:
            # Vision may still show the ball where it was before it went back to the spot.
            on_spot = math.hypot(b[0], b[1]) < 0.05
            self._spot_seen |= on_spot
            if (self._spot_seen and not on_spot) or t_s - self._kickoff_since > KICKOFF_S:
                self.kickoff = None
        out = abs(b[0]) > HALF_LENGTH_M or abs(b[1]) > HALF_WIDTH_M
        if not out:
            self._out_since = None
        elif self._out_since is None:
            self._out_since = t_s
        elif t_s - self._out_since > OUT_S and self.kickoff is None:
            # Out of the field (not in a goal): back in, 0.3 m inside the lines.
            self._out_since = None
            x = clamp(b[0], -HALF_LENGTH_M + 0.3, HALF_LENGTH_M - 0.3)
            y = clamp(b[1], -HALF_WIDTH_M + 0.3, HALF_WIDTH_M - 0.3)
            self.count(self.client.teleport_ball(x, y, teleport_safely=True))
            self.throw_ins += 1
        moved = self._ball_at is None or math.dist(b, self._ball_at) > 0.1
        if moved:
            self._ball_at, self._still_since = b, t_s
        elif self._still_since is not None and t_s - self._still_since > STALL_S:
            self.stall_restarts += 1
            last = self._last_kickoff
            self.restart(t_s, ssl.Team.YELLOW if last == ssl.Team.BLUE else ssl.Team.BLUE)

    def restart(self, t_s: float, kickoff: ssl.Team) -> None:
        """The ball back on the centre spot (robots there moved aside), ``kickoff``'s."""
        self.count(self.client.teleport_ball(0.0, 0.0, teleport_safely=True))
        self._ball_at, self._still_since = None, None
        self.kickoff, self._kickoff_since, self._spot_seen = kickoff, t_s, False
        self._last_kickoff = kickoff


def play_lockstep(
    client: ssl.SslClient, referee: ssl.RefereeReceiver, duration_s: float, goals: int
) -> Match:
    """The match in lockstep: yellow's commands held, blue's with each step's request; vision
    from the steps' detection frames. It ends early after ``goals`` goals (0: never)."""
    match, seen = Match(client), ssl.VisionState()
    blue, yellow = TeamAi(ssl.Team.BLUE), TeamAi(ssl.Team.YELLOW)
    steps = int(round(duration_s / PERIOD_S))
    # A first step with no commands gives the first frames.
    for frame in client.sync("control", PERIOD_S).detection:
        seen.update(frame)
    for k in range(1, steps):
        t_s = k * PERIOD_S
        match.count(client.command("yellow", yellow.commands(seen, match.kickoff)))
        answer = client.sync("blue", PERIOD_S, blue.commands(seen, match.kickoff))
        match.count(answer)
        for frame in answer.detection:
            seen.update(frame)
        match.referee(referee.poll(), t_s)
        match.watch_ball(seen, t_s)
        match.t_s = t_s + PERIOD_S
        if 0 < goals <= len(match.goals):
            break
    return match


def play_real_time(
    client: ssl.SslClient,
    vision: ssl.VisionReceiver,
    referee: ssl.RefereeReceiver,
    duration_s: float,
    goals: int,
) -> Match:
    """The match at the simulator's pace: commands every control period of wall time."""
    match = Match(client)
    blue, yellow = TeamAi(ssl.Team.BLUE), TeamAi(ssl.Team.YELLOW)
    start = time.monotonic()
    tick = start
    while (now := time.monotonic()) - start < duration_s:
        vision.poll()
        match.count(client.command("yellow", yellow.commands(vision.state, match.kickoff)))
        match.count(client.command("blue", blue.commands(vision.state, match.kickoff)))
        match.referee(referee.poll(), now - start)
        match.watch_ball(vision.state, now - start)
        match.t_s = now - start
        if 0 < goals <= len(match.goals):
            break
        tick += PERIOD_S
        time.sleep(max(0.0, tick - time.monotonic()))
    return match


def main(argv: Optional[Sequence[str]] = None) -> int:
    p = argparse.ArgumentParser(description="A scripted six-against-six match over the SSL ports.")
    p.add_argument("--duration", type=float, default=60.0, help="simulated seconds (60)")
    p.add_argument("--goals", type=int, default=0, help="end after this many goals (0: never)")
    p.add_argument("--real-time", action="store_true", help="play at the simulator's pace")
    p.add_argument("--serve", action="store_true", help="start omniloop ssl (free ports)")
    p.add_argument("--binary", help="the omniloop binary for --serve")
    p.add_argument("--scenario", default=str(SCENARIO), help="the scenario for --serve")
    p.add_argument("--seed", type=int, help="the simulator's seed for --serve")
    p.add_argument("--control", default="127.0.0.1:10300", help="simulation-control address")
    p.add_argument("--blue", default="127.0.0.1:10301", help="blue's robot-control address")
    p.add_argument("--yellow", default="127.0.0.1:10302", help="yellow's robot-control address")
    p.add_argument("--vision", default="224.5.23.2:10020", help="where vision arrives (real time)")
    p.add_argument("--referee", default="224.5.23.1:10003", help="where the referee arrives")
    p.add_argument("--json", action="store_true", help="print the result as one JSON line")
    args = p.parse_args(argv)

    wall = time.monotonic()
    vision: Optional[ssl.VisionReceiver]
    if args.serve:
        # In lockstep the steps' answers hold vision's frames: its packets go unread here.
        vision = ssl.VisionReceiver(("127.0.0.1", 0))
        referee = ssl.RefereeReceiver(("127.0.0.1", 0))
        extra = ["--no-cameras"] + (["--seed", str(args.seed)] if args.seed is not None else [])
        with ssl.serve(
            args.scenario,
            lockstep=not args.real_time,
            extra_args=extra,
            binary=args.binary,
            vision=vision.address,
            referee=referee.address,
        ) as served, served.client() as client:
            match = play(client, vision, referee, args)
    else:
        vision = ssl.VisionReceiver(args.vision) if args.real_time else None
        referee = ssl.RefereeReceiver(args.referee)
        with ssl.SslClient(args.control, args.blue, args.yellow) as client:
            match = play(client, vision, referee, args)
    wall = time.monotonic() - wall

    result = {
        "blue": match.score[0],
        "yellow": match.score[1],
        "goals": [{"t_s": round(t, 2), "team": team} for t, team in match.goals],
        "errors": len(match.errors),
        "error_codes": sorted(set(match.errors)),
        "stall_restarts": match.stall_restarts,
        "throw_ins": match.throw_ins,
        "simulated_s": round(match.t_s, 2),
        "wall_s": round(wall, 2),
    }
    if args.json:
        print(json.dumps(result))
    else:
        goals = ", ".join(f"{team} at {t:.1f} s" for t, team in match.goals) or "none"
        print(f"final score: blue {match.score[0]} yellow {match.score[1]} (goals: {goals})")
        print(
            f"errors answered: {len(match.errors)}; {match.t_s:.1f} s simulated in {wall:.1f} s"
        )
    return 0


def play(
    client: ssl.SslClient,
    vision: Optional[ssl.VisionReceiver],
    referee: ssl.RefereeReceiver,
    args: argparse.Namespace,
) -> Match:
    """Puts the ball on the centre spot and plays ``args.duration`` seconds (vision's
    packets are read in real time only)."""
    client.teleport_ball(0.0, 0.0)
    if args.real_time:
        assert vision is not None
        return play_real_time(client, vision, referee, args.duration, args.goals)
    return play_lockstep(client, referee, args.duration, args.goals)


if __name__ == "__main__":
    sys.exit(main())
