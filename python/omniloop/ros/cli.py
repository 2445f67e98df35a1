"""``omniloop-ros SCENARIO``: a scenario's robots on ROS 2 topics (see ``docs/ros.md``)."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import List, Optional

import omniloop

from . import INSTALL_HINT


def parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(
        prog="omniloop-ros",
        description="Run an omniloop scenario as a ROS 2 node: each robot's cameras, odometry, "
        "free space (scan) and ground truth on topics under its name, driven by cmd_vel (with "
        "a kicker also kick and dribbler in, ball_in_dribbler out), the ball's truth on "
        "/ground_truth/ball, /clock on simulation time.",
        epilog="ROS arguments go after --ros-args, e.g. --ros-args -p seed:=3",
    )
    p.add_argument("scenario", type=Path, help="the scenario file")
    mode = p.add_mutually_exclusive_group()
    mode.add_argument(
        "--lockstep",
        action="store_true",
        help="each cycle waits for a command answering the last frame: the same seed and node "
        "give the same trajectory, however slow the node",
    )
    mode.add_argument(
        "--realtime",
        nargs="?",
        type=float,
        const=1.0,
        default=1.0,
        metavar="FACTOR",
        help="paced to the wall clock, FACTOR simulation seconds a second "
        "(default 1; 0: as fast as it goes)",
    )
    p.add_argument(
        "--robot",
        choices=["python", "builtin", "ssl"],
        default="python",
        help="python: the robots take cmd_vel (default); builtin: omniloop's own software "
        "drives and the node only publishes; ssl: a Small-Size team's AI drives them over the "
        "SSL simulation protocol (the scenario's [ssl] ports, as omniloop ssl serves them) and "
        "the node publishes every robot's cameras",
    )
    p.add_argument(
        "--seed", type=int, help="the episode's seed (default: the scenario's; the seed parameter)"
    )
    p.add_argument("--renderer", choices=["cpu", "gpu", "auto"], default="cpu")
    p.add_argument(
        "--twist-stamped", action="store_true", help="cmd_vel is geometry_msgs/TwistStamped"
    )
    p.add_argument(
        "--cmd-vel-timeout",
        type=float,
        default=0.5,
        metavar="S",
        help="a command older than S simulation seconds stops the robot (default 0.5)",
    )
    p.add_argument(
        "--lockstep-timeout",
        type=float,
        default=10.0,
        metavar="S",
        help="wall seconds a lockstep cycle waits for its commands (default 10)",
    )
    p.add_argument(
        "--out", type=Path, help="write the run's files here when it ends (as omniloop run does)"
    )
    p.add_argument(
        "--exit-at-end",
        action="store_true",
        help="exit when the run is over (else wait for ~/reset)",
    )
    return p


def main(argv: Optional[List[str]] = None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    ros_args: List[str] = []
    if "--ros-args" in argv:
        k = argv.index("--ros-args")
        argv, ros_args = argv[:k], argv[k:]
    args = parser().parse_args(argv)
    # The scenario first: a bad one exits 2 with the CLI's message before any node starts.
    try:
        scenario = omniloop.Scenario.load(args.scenario)
    except omniloop.ScenarioError as e:
        print(f"error: {e}", file=sys.stderr)
        return 2
    except OSError as e:
        print(f"error: {e}", file=sys.stderr)
        return 2
    for name, value in [
        ("--cmd-vel-timeout", args.cmd_vel_timeout),
        ("--lockstep-timeout", args.lockstep_timeout),
        ("--realtime", args.realtime),
        ("--seed", 0 if args.seed is None else args.seed),
    ]:
        if not value >= 0:
            print(f"error: {name} must be a number >= 0 (got {value})", file=sys.stderr)
            return 2
    if args.robot == "ssl" and args.lockstep:
        print(
            "error: --robot ssl is paced by the clock (the team's AI keeps its own time): "
            "leave out --lockstep (omniloop ssl --lockstep steps on the protocol's sync requests)",
            file=sys.stderr,
        )
        return 2
    try:
        import rclpy

        from .bridge import Bridge, BridgeOptions
    except ImportError as e:
        print(f"error: {INSTALL_HINT} ({e})", file=sys.stderr)
        return 1
    options = BridgeOptions(
        lockstep=args.lockstep,
        realtime_factor=args.realtime,
        robot=args.robot,
        seed=args.seed,
        renderer=args.renderer,
        twist_stamped=args.twist_stamped,
        cmd_vel_timeout_s=args.cmd_vel_timeout,
        lockstep_timeout_s=args.lockstep_timeout,
        out=args.out,
        exit_at_end=args.exit_at_end,
    )
    rclpy.init(args=["omniloop-ros", *ros_args])
    bridge = None
    try:
        bridge = Bridge(scenario, options)
        bridge.spin()
    except KeyboardInterrupt:
        pass
    except (RuntimeError, ValueError) as e:
        print(f"error: {e}", file=sys.stderr)
        return 1
    finally:
        if bridge is not None:
            if bridge.sim is not None and not bridge.written:
                bridge.finish()
            bridge.close()
        rclpy.try_shutdown()
    return 0


if __name__ == "__main__":
    sys.exit(main())
