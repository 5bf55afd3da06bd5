"""The backend's ROS 2 plumbing: publishers, subscriptions, service clients, and
the latest odometry, joint states, object report and bumper stop, each with its
arrival time.

The skill logic in `backend.py` reads snapshots from here and never sees rclpy
types, which keeps the control loops short and the safety rules in one place.
"""

from __future__ import annotations

import math
import threading
import time
from collections.abc import Callable, Collection
from dataclasses import dataclass
from typing import Any

from agent.robot import CancelToken, Pose
from agent.ros2.config import RosConfig
from agent.ros2.geometry import quaternion_from_yaw, yaw_from_quaternion
from agent.ros2.messages import BumperStop, FormatError, ObjectReport, decode_bumper, decode_objects
from agent.ros2.node_thread import NodeThread
from rsl.profile import PRIMITIVES, Primitive, Profile

DISCOVERY_FLOOR = 2.0  # s a long-running backend still waits for a service or subscriber
# Discovery is not symmetric: we can match a server that just appeared before it has matched our
# response reader, and Fast DDS drops a reply to a reader its server has not matched within 100 ms
# (ros2/ros2#1253). Nothing in ROS shows the server's side of the match, and a Trigger such as
# dock must not be sent twice, so a request waits until its server has been in sight this long:
# one retransmission of a lost discovery announcement (Fast DDS repeats them every 1 s) and margin.
SERVER_SETTLE = 1.5  # s
SERVER_WATCH_PERIOD = 0.1  # s between looks at whether each client's server is in sight


@dataclass(frozen=True)
class Odometry:
    pose: Pose
    linear: float  # m/s, forward
    angular: float  # rad/s, counter-clockwise
    received: float  # time.monotonic() on arrival


@dataclass(frozen=True)
class ServiceReply:
    success: bool
    message: str


class ServiceError(RuntimeError):
    """A service that is missing, slow, or was abandoned because of a cancel."""


class RobotLink:
    def __init__(self, config: RosConfig, node_name: str = "nrtrans_backend",
                 primitives: frozenset[str] = frozenset(PRIMITIVES)) -> None:
        from geometry_msgs.msg import PoseStamped, Twist
        from nav_msgs.msg import Odometry as OdometryMsg
        from rclpy.qos import QoSProfile, ReliabilityPolicy, qos_profile_sensor_data
        from sensor_msgs.msg import JointState
        from std_msgs.msg import String
        from std_srvs.srv import Trigger
        from trajectory_msgs.msg import JointTrajectory

        self.config = config
        self._started = time.monotonic()
        self._closed = False
        self._lock = threading.Lock()
        self._odom_arrived = threading.Condition(self._lock)
        self._odom: Odometry | None = None
        self._joints: dict[str, float] = {}
        self._joints_received = 0.0
        self._objects: ObjectReport | None = None
        self._objects_received = 0.0
        self._objects_error = ""
        self._bumper_stop: BumperStop | None = None
        self._bumper_received = 0.0
        self._clients: list[Any] = []
        self._server_seen: dict[Any, float] = {}  # client -> time.monotonic() its server came into sight

        self._ros = NodeThread(node_name)
        node = self._ros.node
        reliable = QoSProfile(depth=10, reliability=ReliabilityPolicy.RELIABLE)
        self._twist_type = Twist
        self._pose_type = PoseStamped
        self._trajectory_type = JointTrajectory
        self._reliable = reliable
        needed = interfaces_needed(primitives)
        self._cmd_vel = node.create_publisher(Twist, config.cmd_vel, reliable)
        self._publishers: dict[str, Any] = {"cmd_vel": self._cmd_vel}
        if "goal" in needed:
            self._publishers["goal"] = node.create_publisher(PoseStamped, config.goal_pose, reliable)
        if "head" in needed:
            self._publishers["head"] = node.create_publisher(JointTrajectory, config.head_trajectory, reliable)
        if "gripper" in needed:
            self._publishers["gripper"] = node.create_publisher(JointTrajectory, config.gripper_trajectory,
                                                                reliable)
        # Best-effort subscriptions match both reliable and best-effort publishers,
        # which is what real robot drivers use for these streams.
        node.create_subscription(OdometryMsg, config.odom, self._on_odom, qos_profile_sensor_data)
        node.create_subscription(JointState, config.joint_states, self._on_joints, qos_profile_sensor_data)
        node.create_subscription(String, config.objects_topic, self._on_objects,
                                 QoSProfile(depth=1, reliability=ReliabilityPolicy.BEST_EFFORT))
        # Reliable: a bumper stop is an event, not a stream whose next message would make up for a lost one.
        node.create_subscription(String, config.bumper, self._on_bumper, reliable)
        self._perceive = self.client(Trigger, config.perceive_service) if "perception" in needed else None
        self._grasp = self.client(Trigger, config.grasp_service) if "gripper" in needed else None
        self._trigger_request = Trigger.Request
        # Watched from the start, so a server found long before its first call is not made to wait.
        node.create_timer(SERVER_WATCH_PERIOD, self._watch_servers)

    # -- incoming --------------------------------------------------------------

    def _on_odom(self, msg: object) -> None:
        pose = msg.pose.pose  # type: ignore[attr-defined]
        twist = msg.twist.twist  # type: ignore[attr-defined]
        q = pose.orientation
        odom = Odometry(
            pose=Pose(pose.position.x, pose.position.y, yaw_from_quaternion(q.x, q.y, q.z, q.w)),
            linear=twist.linear.x, angular=twist.angular.z, received=time.monotonic(),
        )
        with self._lock:
            self._odom = odom
            self._odom_arrived.notify_all()

    def _on_joints(self, msg: object) -> None:
        names = msg.name  # type: ignore[attr-defined]
        positions = msg.position  # type: ignore[attr-defined]
        with self._lock:
            for name, position in zip(names, positions, strict=False):
                self._joints[name] = float(position)
            self._joints_received = time.monotonic()

    def _on_objects(self, msg: object) -> None:
        try:
            report = decode_objects(msg.data, f"objects topic {self.config.objects_topic}")  # type: ignore[attr-defined]
        except FormatError as exc:
            with self._lock:
                self._objects_error = str(exc)
            return
        with self._lock:
            self._objects = report
            self._objects_received = time.monotonic()
            self._objects_error = ""

    def _on_bumper(self, msg: object) -> None:
        try:
            stop = decode_bumper(msg.data, f"bumper topic {self.config.bumper}")  # type: ignore[attr-defined]
        except FormatError as exc:
            # An unreadable report names no obstacle to fail a step with; a robot whose bumper
            # cut the drive stands still, and the step's own time budget still ends it.
            self._ros.node.get_logger().warning(f"ignored a bumper report: {exc}", throttle_duration_sec=1.0)
            return
        with self._lock:
            self._bumper_stop = stop
            self._bumper_received = time.monotonic()

    # -- snapshots -------------------------------------------------------------

    def odometry(self) -> Odometry | None:
        with self._lock:
            return self._odom

    def wait_for_odometry(self, timeout: float, newer_than: float = 0.0) -> Odometry | None:
        deadline = time.monotonic() + timeout
        with self._lock:
            while self._odom is None or self._odom.received <= newer_than:
                remaining = deadline - time.monotonic()
                if remaining <= 0:
                    return None
                self._odom_arrived.wait(remaining)
            return self._odom

    def joints(self) -> tuple[dict[str, float], float]:
        """Latest joint positions and when they last arrived (0.0: never)."""
        with self._lock:
            return dict(self._joints), self._joints_received

    def objects(self) -> tuple[ObjectReport | None, str]:
        """The latest object report, and the last format error if the newest was malformed."""
        with self._lock:
            return self._objects, self._objects_error

    def objects_received(self) -> float:
        with self._lock:
            return self._objects_received

    def bumper_stop(self, since: float) -> BumperStop | None:
        """The latest bumper stop, if one arrived after `since` (a time.monotonic())."""
        with self._lock:
            return self._bumper_stop if self._bumper_received > since else None

    def await_bumper_quiet(self, quiet: float, limit: float) -> None:
        """Wait until no bumper stop has arrived for `quiet` s, at most `limit` s."""
        deadline = time.monotonic() + limit
        while True:
            with self._lock:
                last = self._bumper_received
            now = time.monotonic()
            if now - last >= quiet or now >= deadline:
                return
            time.sleep(0.01)

    # -- outgoing --------------------------------------------------------------

    def send_twist(self, linear: float, angular: float) -> None:
        if self._closed:
            return
        msg = self._twist_type()
        msg.linear.x = float(linear)
        msg.angular.z = float(angular)
        self._cmd_vel.publish(msg)

    def send_zero_twist(self) -> None:
        # Repeated because a driver that samples cmd_vel best-effort may drop one.
        for _ in range(3):
            self.send_twist(0.0, 0.0)

    def send_goal(self, x: float, y: float, heading: float) -> None:
        if self._closed:
            return
        msg = self._pose_type()
        msg.header.frame_id = self.config.world_frame
        msg.header.stamp = self._ros.node.get_clock().now().to_msg()
        msg.pose.position.x = float(x)
        msg.pose.position.y = float(y)
        qx, qy, qz, qw = quaternion_from_yaw(heading)
        msg.pose.orientation.x, msg.pose.orientation.y = qx, qy
        msg.pose.orientation.z, msg.pose.orientation.w = qz, qw
        goal = self._publishers.get("goal")
        if goal is not None:
            goal.publish(msg)

    def send_head(self, pan: float, tilt: float, duration: float) -> None:
        self.send_trajectory(self._publishers["head"], [self.config.head_pan_joint, self.config.head_tilt_joint],
                             [pan, tilt], duration)

    def send_gripper(self, position: float, duration: float) -> None:
        self.send_trajectory(self._publishers["gripper"], [self.config.gripper_joint], [position], duration)

    def publisher(self, msg_type: Any, topic: str) -> Any:
        """A reliable publisher on `topic`, for a skill bound to a topic or joint trajectory."""
        return self._ros.node.create_publisher(msg_type, topic, self._reliable)

    def client(self, srv_type: Any, service: str) -> Any:
        client = self._ros.node.create_client(srv_type, service)
        with self._lock:
            self._clients.append(client)
        return client

    def send_trajectory(self, publisher: object, joints: list[str], positions: list[float],
                        duration: float) -> None:
        from builtin_interfaces.msg import Duration
        from trajectory_msgs.msg import JointTrajectoryPoint

        if self._closed:
            return
        msg = self._trajectory_type()
        msg.joint_names = joints
        point = JointTrajectoryPoint()
        point.positions = [float(p) for p in positions]
        seconds = max(duration, 0.0)
        point.time_from_start = Duration(sec=int(seconds), nanosec=int((seconds % 1.0) * 1e9))
        msg.points = [point]
        publisher.publish(msg)  # type: ignore[attr-defined]

    def call_perceive(self, cancel: CancelToken) -> ServiceReply:
        return self.call(self._perceive, self.config.perceive_service, cancel)

    def call_grasp(self, cancel: CancelToken) -> ServiceReply:
        return self.call(self._grasp, self.config.grasp_service, cancel)

    def call(self, client: object, name: str, cancel: CancelToken, request: object | None = None) -> ServiceReply:
        """Call a service whose response has `success` and `message` (std_srvs Trigger, SetBool)."""
        self._await_server(client, name, cancel)
        timeout = self.config.service_timeout
        future = client.call_async(request or self._trigger_request())  # type: ignore[attr-defined]
        answered = threading.Event()
        future.add_done_callback(lambda _f: answered.set())
        deadline = time.monotonic() + timeout
        while not answered.wait(0.02):
            if cancel.is_set() or time.monotonic() > deadline:
                client.remove_pending_request(future)  # type: ignore[attr-defined]
                if cancel.is_set():
                    raise ServiceError(f"call to {name} abandoned: {cancel.reason}")
                raise ServiceError(f"service {name} did not answer within {timeout:g} s")
        response = future.result()
        return ServiceReply(bool(response.success), str(response.message))

    def _await_server(self, client: object, name: str, cancel: CancelToken) -> None:
        """Return once `client`'s server has been in sight for SERVER_SETTLE s; raise if it does not
        appear within `discovery_wait` or the call is cancelled first, before anything was sent."""
        deadline = time.monotonic() + self.discovery_wait()
        while True:
            if cancel.is_set():
                raise ServiceError(f"call to {name} abandoned: {cancel.reason}")
            now = time.monotonic()
            seen = self._server_in_sight(client, now)
            if seen is not None and now - seen >= SERVER_SETTLE:
                return
            if seen is None and now > deadline:
                raise ServiceError(f"service {name} is not available; is the robot's driver "
                                   "(or `nrtrans sim-bridge`) running and offering it?")
            time.sleep(0.02)

    def _server_in_sight(self, client: Any, now: float) -> float | None:
        """Since when `client`'s server has been discovered without a break, or None while it is not."""
        ready = client.service_is_ready()
        with self._lock:
            if not ready:
                self._server_seen.pop(client, None)
                return None
            return self._server_seen.setdefault(client, now)

    def _watch_servers(self) -> None:
        now = time.monotonic()
        with self._lock:
            clients = list(self._clients)
        for client in clients:
            self._server_in_sight(client, now)

    def discovery_wait(self) -> float:
        """Seconds to wait for a service or a subscriber to be discovered before calling it missing.

        Discovery on a loaded two-core machine has taken over 2 s, so a backend just started is
        given the whole discovery timeout; one that has run longer has seen the graph already.
        """
        left = self.config.discovery_timeout - (time.monotonic() - self._started)
        return max(DISCOVERY_FLOOR, left)

    def await_subscriber(self, count: Callable[[], int]) -> bool:
        """Wait, up to `discovery_wait`, until `count` (a publisher's subscriptions) is above 0; whether it was."""
        deadline = time.monotonic() + self.discovery_wait()
        while count() == 0:
            if time.monotonic() > deadline:
                return False
            time.sleep(0.05)
        return True

    def listeners(self, publisher: str) -> int:
        """How many subscriptions match one of our publishers: cmd_vel, goal, head or gripper."""
        return int(self._publishers[publisher].get_subscription_count())

    def close(self) -> None:
        # After this, sends are no-ops: a step still unwinding in another thread
        # must not publish through a destroyed node.
        self._closed = True
        self._ros.close()


def primitives_used(profile: Profile) -> frozenset[str]:
    """The robot primitives the profile's skills are bound to."""
    return frozenset(s.binding.name for s in profile.skills if isinstance(s.binding, Primitive))


# The optional interfaces of the robot and the primitives that use each. The backend opens, and the
# simulator's bridge offers, one only when a skill is bound to such a primitive: a base-only robot
# has no head topic. Both read this table, so the two sides cannot disagree on what a robot needs.
_INTERFACE_USERS = {
    "goal": frozenset({"navigate", "approach_object"}),
    "head": frozenset({"pan", "tilt"}),
    "gripper": frozenset({"grasp_object"}),
    # Grasping or approaching an object not yet known looks for it first.
    "perception": frozenset({"perceive_objects", "approach_object", "grasp_object"}),
}


def interfaces_needed(primitives: Collection[str]) -> frozenset[str]:
    """Which of "goal", "head", "gripper" (trajectory and grasp service) and "perception" these primitives use."""
    given = frozenset(primitives)
    return frozenset(name for name, users in _INTERFACE_USERS.items() if users & given)


def distance(a: Pose, x: float, y: float) -> float:
    return math.hypot(x - a.x, y - a.y)
