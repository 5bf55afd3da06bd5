"""`SimBridge`: the pybullet robot served over the ROS 2 interfaces a real robot offers.

It plays the robot's drivers: a base controller on cmd_vel (with a command
timeout, as diff-drive controllers have), odometry and joint states at a fixed
rate, joint trajectory controllers for the head and gripper, a goal-pose
follower, and the perceive and grasp services and objects topic that
docs/ros2.md defines, each only when a skill of the profile is bound to the
primitive that uses it, and the bumper topic, on which the world's bumper
reports each stop. The backend cannot tell it from a robot.

All callbacks and the physics run on the one executor thread, so the world is
never touched from two threads at once.
"""

from __future__ import annotations

import math
import time
from collections.abc import Iterable
from typing import Any

from agent.ros2.config import RosConfig
from agent.ros2.geometry import quaternion_from_yaw, wrap_angle, yaw_from_quaternion
from agent.ros2.goal_follower import Goal, GoalFollower
from agent.ros2.link import interfaces_needed, primitives_used
from agent.ros2.messages import BumperStop, Footprint, encode_bumper, encode_held, encode_objects
from agent.ros2.node_thread import NodeThread
from agent.sim.world import GRASP_BEARING, SimWorld
from rsl.profile import Profile

PUBLISH_HZ = 50.0
OBJECTS_EVERY = 10  # ticks: the objects topic goes out at 5 Hz
CMD_VEL_TIMEOUT = 0.5  # s of wall time without cmd_vel before the base is stopped
MAX_CATCH_UP = 0.25  # s of simulated time one tick may make up after a stall
GRIPPER_SPEED = 0.2  # m/s, the finger speed the joint state reports
RESET_SERVICE = "/sim_bridge/reset"


class SimBridge:
    def __init__(self, profile: Profile, world_factory: Any, *, realtime_factor: float = 1.0,
                 config: RosConfig | None = None, node_name: str = "nrtrans_sim_bridge") -> None:
        from geometry_msgs.msg import PoseStamped, Twist
        from nav_msgs.msg import Odometry
        from rclpy.qos import QoSProfile, ReliabilityPolicy
        from sensor_msgs.msg import JointState
        from std_msgs.msg import String
        from std_srvs.srv import Trigger
        from trajectory_msgs.msg import JointTrajectory

        if realtime_factor <= 0:
            raise ValueError(f"the real-time factor must be positive, got {realtime_factor:g}")
        self.profile = profile
        self.config = config or RosConfig.from_profile(profile)
        self.realtime_factor = realtime_factor
        self._new_world = world_factory
        self.world: SimWorld = world_factory()
        self._follower = GoalFollower(profile.motion)
        self._reset_state()
        self._odometry_type, self._joint_state_type, self._string_type = Odometry, JointState, String

        self._ros = NodeThread(node_name)
        node = self._ros.node
        reliable = QoSProfile(depth=10, reliability=ReliabilityPolicy.RELIABLE)
        cfg = self.config
        # The drivers of the primitives the profile's skills are bound to, and no others: a
        # base-only robot's bridge offers no head or gripper. Skills bound to ROS 2 directly are
        # the robot's own interfaces, which the simulator does not model.
        needed = interfaces_needed(primitives_used(profile))
        self._head_joints = "head" in needed
        self._has_gripper = "gripper" in needed
        self._odom = node.create_publisher(Odometry, cfg.odom, reliable)
        self._joints = node.create_publisher(JointState, cfg.joint_states, reliable)
        self._objects = node.create_publisher(String, cfg.objects_topic, reliable)
        self._bumper = node.create_publisher(String, cfg.bumper, reliable)
        node.create_subscription(Twist, cfg.cmd_vel, self._on_cmd_vel, reliable)
        self.interfaces = [cfg.cmd_vel, cfg.odom, cfg.joint_states, cfg.objects_topic, cfg.bumper]
        if "goal" in needed:
            node.create_subscription(PoseStamped, cfg.goal_pose, self._on_goal, reliable)
            self.interfaces.append(cfg.goal_pose)
        if self._head_joints:
            node.create_subscription(JointTrajectory, cfg.head_trajectory, self._on_head, reliable)
            self.interfaces.append(cfg.head_trajectory)
        if self._has_gripper:
            node.create_subscription(JointTrajectory, cfg.gripper_trajectory, self._on_gripper, reliable)
            node.create_service(Trigger, cfg.grasp_service, self._on_grasp)
            self.interfaces += [cfg.gripper_trajectory, cfg.grasp_service]
        if "perception" in needed:
            node.create_service(Trigger, cfg.perceive_service, self._on_perceive)
            self.interfaces.append(cfg.perceive_service)
        node.create_service(Trigger, RESET_SERVICE, self._on_reset)
        self._timer = node.create_timer(1.0 / PUBLISH_HZ, self._tick)

    def _reset_state(self) -> None:
        self._seen: set[str] = set()
        self._cmd = (0.0, 0.0)
        self._cmd_at = -math.inf
        self._follower.clear()
        self._gripper = self.config.gripper_open_position
        self._gripper_target = self._gripper
        self._ticks = 0
        self._bumped = False
        self._last_tick = time.monotonic()
        self._owed = 0.0

    # -- the physics clock -----------------------------------------------------------

    def _tick(self) -> None:
        now = time.monotonic()
        wall = now - self._last_tick
        self._last_tick = now
        world = self.world
        self._owed = min(self._owed + wall * self.realtime_factor, MAX_CATCH_UP)
        steps = int(self._owed / world.dt)
        self._owed -= steps * world.dt
        if self._follower.goal is not None:
            # A goal at the robot's own pose is how clients cancel one; it is reached at once.
            world.set_base_velocity(*self._follower.command(world.base_pose(), steps * world.dt))
        elif now - self._cmd_at > CMD_VEL_TIMEOUT:
            world.set_base_velocity(0.0, 0.0)
        else:
            world.set_base_velocity(*self._cmd)
        contact = None
        for _ in range(steps):
            world.step()
            contact = contact or world.blocked_by
        if steps:
            # One report per stop, not one per tick: the bumper holds the base while the
            # command pushes on, and the backend fails the step at the first report.
            if contact is not None and not self._bumped:
                stop = BumperStop(contact.name, (contact.x, contact.y), self.config.world_frame)
                self._bumper.publish(self._string_type(data=encode_bumper(stop)))
            self._bumped = contact is not None
        self._move_gripper(steps * world.dt)
        self._publish_state()
        self._ticks += 1
        if self._ticks % OBJECTS_EVERY == 0:
            self._publish_objects()

    def _move_gripper(self, elapsed: float) -> None:
        step = GRIPPER_SPEED * elapsed
        self._gripper += max(-step, min(step, self._gripper_target - self._gripper))

    def _publish_state(self) -> None:
        world, cfg = self.world, self.config
        stamp = self._ros.node.get_clock().now().to_msg()
        pose = world.base_pose()
        linear, angular = world.base_velocity()
        odom = self._odometry_type()
        odom.header.stamp = stamp
        odom.header.frame_id = cfg.world_frame
        odom.child_frame_id = "base_link"
        odom.pose.pose.position.x, odom.pose.pose.position.y = pose.x, pose.y
        qx, qy, qz, qw = quaternion_from_yaw(pose.heading)
        orientation = odom.pose.pose.orientation
        orientation.x, orientation.y, orientation.z, orientation.w = qx, qy, qz, qw
        odom.twist.twist.linear.x, odom.twist.twist.angular.z = linear, angular
        self._odom.publish(odom)
        pan, tilt = world.head()
        joints = self._joint_state_type()
        joints.header.stamp = stamp
        names: list[str] = []
        positions: list[float] = []
        if self._head_joints:
            names += [cfg.head_pan_joint, cfg.head_tilt_joint]
            positions += [float(pan), float(tilt)]
        if self._has_gripper:
            names.append(cfg.gripper_joint)
            positions.append(float(self._gripper))
        joints.name, joints.position = names, positions
        self._joints.publish(joints)

    def _publish_objects(self) -> None:
        # Like a perception stack's tracker: the objects seen so far, where they are now.
        world = self.world
        tracked = {name: position for name, position in world.objects().items()
                   if name in self._seen or name == world.holding}
        text = encode_objects(tracked, world.holding, self.config.world_frame, self._footprints(tracked))
        self._objects.publish(self._string_type(data=text))

    # -- commands ----------------------------------------------------------------------

    def _on_cmd_vel(self, msg: Any) -> None:
        self._cmd = (float(msg.linear.x), float(msg.angular.z))
        if self._cmd != (0.0, 0.0):
            # Like a twist multiplexer: driving by hand overrides a goal in progress. A zero
            # Twist does not, because DDS does not order it against a goal on another topic:
            # the zero that ends one step could otherwise cancel the next step's goal.
            self._follower.clear()
        self._cmd_at = time.monotonic()
        if self._follower.goal is None:
            self.world.set_base_velocity(*self._cmd)

    def _on_goal(self, msg: Any) -> None:
        frame = msg.header.frame_id
        if frame and frame not in (self.config.world_frame, "map"):
            self._ros.node.get_logger().warning(
                f"ignored a goal in frame `{frame}`; goals must be in `{self.config.world_frame}`")
            return
        q = msg.pose.orientation
        self._follower.set(Goal(float(msg.pose.position.x), float(msg.pose.position.y),
                                yaw_from_quaternion(q.x, q.y, q.z, q.w)))

    def _on_head(self, msg: Any) -> None:
        target = self._trajectory_end(msg)
        pan, tilt = self.world.head_target
        self.world.set_head_target(target.get(self.config.head_pan_joint, pan),
                                   target.get(self.config.head_tilt_joint, tilt))

    def _on_gripper(self, msg: Any) -> None:
        target = self._trajectory_end(msg).get(self.config.gripper_joint)
        if target is None:
            return
        cfg = self.config
        closed = abs(target - cfg.gripper_closed_position) < abs(target - cfg.gripper_open_position)
        self.world.set_gripper(closed)
        self._gripper_target = cfg.gripper_closed_position if closed else cfg.gripper_open_position

    @staticmethod
    def _trajectory_end(msg: Any) -> dict[str, float]:
        """The final point of a trajectory; this controller goes there at its own joint speed."""
        if not msg.points:
            return {}
        return {name: float(p) for name, p in zip(msg.joint_names, msg.points[-1].positions, strict=False)}

    # -- services ----------------------------------------------------------------------

    def _on_perceive(self, _request: Any, response: Any) -> Any:
        seen = self.world.visible_objects()
        self._seen.update(seen)
        response.success = True
        response.message = encode_objects(seen, frame=self.config.world_frame,
                                          footprints=self._footprints(seen))
        self._publish_objects()
        return response

    def _footprints(self, names: Iterable[str]) -> dict[str, Footprint]:
        wanted = set(names)
        return {o.name: Footprint(o.shape, (o.size[0], o.size[1]), o.yaw)
                for o in self.world.scene.objects if o.name in wanted}

    def _on_grasp(self, _request: Any, response: Any) -> Any:
        world = self.world
        pose = world.base_pose()
        reach = self.profile.motion.reach
        candidates = []
        for name, (x, y, _z) in world.objects().items():
            obj = world.scene.object(name)
            away = math.hypot(x - pose.x, y - pose.y)
            bearing = abs(wrap_angle(math.atan2(y - pose.y, x - pose.x) - pose.heading))
            # The arm is guided by perception, so it only reaches for objects seen before.
            if obj is not None and obj.graspable and name in self._seen and name != world.holding \
                    and away <= reach and bearing <= GRASP_BEARING:
                candidates.append((away, name))
        if not candidates:
            response.success = False
            response.message = (f"no graspable object seen so far is within reach {reach:g} m "
                                "in front of the gripper")
            return response
        name = min(candidates)[1]
        outcome = world.grasp(name)
        response.success = outcome.ok
        response.message = encode_held(name) if outcome.ok else outcome.reason
        if outcome.ok:
            self._gripper_target = self.config.gripper_closed_position
        self._last_tick = time.monotonic()
        return response

    def _on_reset(self, _request: Any, response: Any) -> Any:
        self.world.close()
        self.world = self._new_world()
        self._reset_state()
        response.success = True
        response.message = "the simulated world is back at the scene's start"
        return response

    def close(self) -> None:
        self._ros.close()
        self.world.set_base_velocity(0.0, 0.0)
        self.world.close()
