"""A minimal ROS 2 node that drives an omniloop robot to its goal from `odom` alone.

    omniloop-ros scenarios/ros_smoke.toml --lockstep &      # the simulation
    python python/examples/ros_drive_to_goal.py             # this node

It answers every `odom` message (one a cycle) with a `cmd_vel`: toward the goal (`goal_pose`,
in `map`, where `odom` starts) at up to 0.8 m/s, slowing over the last 0.4 m. It stops when the
odometry stops coming (the run is over: the goal reached, or time up).
"""

import math
import time

import rclpy
from geometry_msgs.msg import PoseStamped, Twist
from nav_msgs.msg import Odometry
from rclpy.node import Node
from rclpy.qos import DurabilityPolicy, QoSProfile

NS = "/omniloop"  # the robot's namespace: the scenario's robot name, or omniloop


class DriveToGoal(Node):
    def __init__(self) -> None:
        super().__init__("drive_to_goal")
        self.goal: tuple[float, float] | None = None
        latched = QoSProfile(depth=1, durability=DurabilityPolicy.TRANSIENT_LOCAL)
        self.create_subscription(PoseStamped, f"{NS}/goal_pose", self.on_goal, latched)
        self.create_subscription(Odometry, f"{NS}/odom", self.on_odom, 5)
        self.cmd = self.create_publisher(Twist, f"{NS}/cmd_vel", 5)
        self.last_odom: float | None = None

    def on_goal(self, msg: PoseStamped) -> None:
        self.goal = (msg.pose.position.x, msg.pose.position.y)

    def on_odom(self, msg: Odometry) -> None:
        p, q = msg.pose.pose.position, msg.pose.pose.orientation
        theta = 2.0 * math.atan2(q.z, q.w)
        self.last_odom = time.monotonic()
        cmd = Twist()
        if self.goal is not None:
            dx, dy = self.goal[0] - p.x, self.goal[1] - p.y
            dist = math.hypot(dx, dy)
            speed = min(0.8, 2.0 * dist)
            c, s = math.cos(theta), math.sin(theta)  # map -> body frame
            cmd.linear.x = speed * (c * dx + s * dy) / max(dist, 1e-9)
            cmd.linear.y = speed * (c * dy - s * dx) / max(dist, 1e-9)
        self.cmd.publish(cmd)


def main() -> None:
    rclpy.init()
    node = DriveToGoal()
    while node.cmd.get_subscription_count() == 0:  # the simulation's cmd_vel is matched
        time.sleep(0.01)
    while rclpy.ok() and (node.last_odom is None or time.monotonic() - node.last_odom < 3.0):
        rclpy.spin_once(node, timeout_sec=0.1)
    node.get_logger().info(f"the run is over; the goal was {node.goal}")
    node.destroy_node()
    rclpy.shutdown()


if __name__ == "__main__":
    main()
