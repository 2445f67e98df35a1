"""omniloop on ROS 2: a node that runs a scenario and publishes each robot's cameras, odometry
and free space on ROS 2 topics, driven by ``cmd_vel``, on simulated time.

From the command line::

    pip install './python[ros]'            # rclpy and messages, where no ROS 2 is installed
    omniloop-ros scenarios/ros_smoke.toml --lockstep

From Python (with rclpy initialised)::

    from omniloop.ros import Bridge, BridgeOptions
    bridge = Bridge(omniloop.Scenario.load(path), BridgeOptions(lockstep=True))
    bridge.spin()

``omniloop.ros.mapping`` (units, frames, the scan and the camera model as ROS takes them)
needs no ROS 2; ``Bridge`` needs rclpy: importing it without rclpy raises ``ImportError`` with
how to install it. See ``docs/ros.md``.
"""

from typing import Any

INSTALL_HINT = (
    "omniloop-ros needs ROS 2's rclpy and messages: pip install 'omniloop[ros]' (Python >= 3.10), "
    "or source a ROS 2 installation"
)


def __getattr__(name: str) -> Any:
    if name in ("Bridge", "BridgeOptions"):
        try:
            from . import bridge
        except ImportError as e:
            raise ImportError(f"{INSTALL_HINT} ({e})") from e
        return getattr(bridge, name)
    raise AttributeError(name)


__all__ = ["Bridge", "BridgeOptions", "INSTALL_HINT"]
