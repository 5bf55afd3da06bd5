"""`Ros2Robot`: the robot interface over standard ROS 2 topics and services.

Skills run by their binding in the profile, never by keyword. Every name of a
primitive's interface comes from the profile's `[ros]` table (see `config.py`
and docs/ros2.md). Driving and turning are closed loop on odometry; panning,
tilting and the gripper go through joint trajectories checked against joint
states; navigating and approaching through a goal pose whose completion is
judged from odometry. A skill with a ROS 2 binding publishes, calls or sends a
trajectory as its binding says (`bindings.py`, docs/skills.md).

Safety rules, each enforced in one place:
- every base motion ends in a zero Twist, however it ends (done, cancel,
  emergency stop, error, timeout, stale odometry);
- odometry older than `odom_timeout` while moving stops the base and fails
  the step;
- a stop by the robot's bumper during a base motion fails the step at once,
  naming the obstacle;
- `stop()` takes the same lock as the control loops' publishing, so no
  motion command can slip out after the emergency stop's zero Twist.
"""

from __future__ import annotations

import math
import threading
import time
from collections.abc import Callable

from agent.primitives import primitive_step
from agent.robot import CancelToken, Outcome, Pose, RobotState, SkillCalls, approach_first
from agent.ros2.bindings import BindingFailure, BoundSkills
from agent.ros2.config import RosConfig
from agent.ros2.geometry import footprint_radius, wrap_angle
from agent.ros2.link import Odometry, RobotLink, ServiceError, primitives_used
from agent.ros2.messages import BumperStop, Footprint, FormatError, decode_held, decode_objects
from agent.ros2.motion import Limits, move_budget, next_speed
from rsl.profile import Profile, RosBinding, Skill

CONTROL_PERIOD = 0.02  # s, 50 Hz: well inside the 0.2 s the robot has to stop after a cancel
LINEAR_TOLERANCE = 0.002  # m; the contract is 2 cm, the rest is margin for coasting
ANGULAR_TOLERANCE = math.radians(0.15)  # the contract is 1 degree
GOAL_GIVE_UP = 2.0  # s standing still short of a goal, after moving, before the step fails
JOINT_TOLERANCE = 0.01  # rad, or m for the gripper
STILL_LINEAR = 0.01  # m/s; slower than this counts as standing still
STILL_ANGULAR = 0.02  # rad/s
FIRST_MESSAGE_WAIT = 2.0  # s to wait for the first joint states or objects after connecting
# Reports of a bumper stop can still be in flight when the step it failed has ended, so a step
# starts once none has arrived for a while. 0.1 s is five ticks of the simulator bridge, and far
# above DDS latency on a link fit to drive a robot over.
BUMPER_QUIET = 0.1  # s without a new bumper stop
BUMPER_QUIET_LIMIT = 1.0  # s at most that a step waits for it


class RobotUnavailable(RuntimeError):
    """No robot answers on the configured topics."""


class StepFailure(Exception):
    """Ends a step with a failed outcome; the message is the reason."""


class Ros2Robot(SkillCalls):
    backend_name = "ros2"

    def __init__(self, profile: Profile, *, config: RosConfig | None = None,
                 node_name: str = "nrtrans_backend", connect_timeout: float | None = None) -> None:
        self.profile = profile
        self.config = config or RosConfig.from_profile(profile)
        motion = profile.motion
        self._linear = Limits(motion.max_linear_speed, motion.max_linear_accel, gain=3.0, creep=0.02)
        self._angular = Limits(motion.max_angular_speed, motion.max_angular_accel, gain=3.0, creep=0.03)
        self._known: dict[str, tuple[float, float]] = {}
        self._footprints: dict[str, Footprint] = {}
        self._holding: str | None = None
        self._held_since = 0.0
        self._stops = 0
        self._generation = 0
        self._publish_lock = threading.Lock()
        self._closed = False
        self._link = RobotLink(self.config, node_name, primitives_used(profile))
        self._bound = BoundSkills(self._link, profile)
        wait = self.config.connect_timeout if connect_timeout is None else connect_timeout
        if self._link.wait_for_odometry(wait) is None:
            self._link.close()
            raise RobotUnavailable(
                f"no robot: no odometry arrived on {self.config.odom} within {wait:g} s.\n"
                "  Start the robot's driver, or `nrtrans sim-bridge` for the simulator, and check that "
                "both sides use the same ROS_DOMAIN_ID and ROS_AUTOMATIC_DISCOVERY_RANGE "
                f"(try `ros2 topic hz {self.config.odom}`)."
            )

    # -- skills, by binding --------------------------------------------------------

    def perform(self, skill: Skill, args: tuple[float | str, ...], *,
                cancel: CancelToken | None = None) -> Outcome:
        """Run `skill` by its binding: a robot primitive, or its ROS 2 topic, service or trajectory."""
        binding = skill.binding
        if isinstance(binding, RosBinding):
            ros = binding
            return self._guarded(cancel, lambda token: self._bound.perform(skill.keyword, ros, skill.params,
                                                                           args, token))
        if binding is None:
            return Outcome.failed(f"the ROS 2 backend cannot run `{skill.keyword}`: it declares no binding in "
                                  f"profile {self.profile.name}")
        return self._guarded(cancel, primitive_step(self, skill, binding, args))

    def _navigate(self, x: float, y: float, token: CancelToken, statement: str) -> Outcome:
        self._check_workspace(x, y, statement)
        start = self._fresh_odometry().pose
        far = math.hypot(x - start.x, y - start.y)
        heading = math.atan2(y - start.y, x - start.x) if far > self.config.goal_tolerance else start.heading
        self._drive_to_goal(x, y, heading, token)
        here = self._fresh_odometry().pose
        return Outcome.done(f"at ({here.x:.2f}, {here.y:.2f})")

    def _approach(self, name: str, token: CancelToken) -> Outcome:
        ox, oy = self._object_position(name, token)
        here = self._fresh_odometry().pose
        away = math.hypot(ox - here.x, oy - here.y)
        heading = math.atan2(oy - here.y, ox - here.x) if away > 1e-3 else here.heading
        standoff = self.profile.motion.standoff + self._edge(name, heading + math.pi)
        x, y = ox - standoff * math.cos(heading), oy - standoff * math.sin(heading)
        self._check_workspace(x, y, f"the stand-off point in front of {name}")
        self._drive_to_goal(x, y, heading, token)
        # Navigation stacks settle headings loosely (Nav2: 0.25 rad by default), so the
        # final turn to face the object is closed loop on odometry like any turn.
        here = self._fresh_odometry().pose
        facing = math.atan2(oy - here.y, ox - here.x)
        error = wrap_angle(facing - here.heading)
        if abs(error) > ANGULAR_TOLERANCE:
            self._turn(abs(error), math.copysign(1.0, error), token, f"the turn to face {name}")
        return Outcome.done(f"stopped {self.profile.motion.standoff:g} m in front of {name}, facing it")

    def _perceive(self, token: CancelToken) -> Outcome:
        reply = self._link.call_perceive(token)
        if not reply.success:
            raise StepFailure(f"perception failed: {reply.message}")
        report = decode_objects(reply.message, f"reply of {self.config.perceive_service}")
        seen = report.objects
        self._known.update(seen)
        self._footprints.update(report.footprints)
        if not seen:
            return Outcome.done("saw no objects")
        return Outcome.done("saw " + ", ".join(sorted(seen)))

    def _grasp(self, name: str, token: CancelToken) -> Outcome:
        if self._holding_now() is not None:
            raise StepFailure(f"cannot grasp {name}: already holding {self._holding_now()}; "
                              "the gripper holds one object at a time")
        ox, oy = self._object_position(name, token)
        here = self._fresh_odometry().pose
        away = math.hypot(ox - here.x, oy - here.y)
        reach = self.profile.motion.reach
        if away > reach:
            raise StepFailure(f"{name} is {away:.2f} m away, out of reach {reach:g} m; "
                              f"{approach_first(self.profile, name)}")
        self._check_nearest(name, away, here)
        self._move_gripper(self.config.gripper_open_position, token)
        reply = self._link.call_grasp(token)
        if not reply.success:
            raise StepFailure(f"grasping {name} failed: {reply.message}")
        held = decode_held(reply.message, f"reply of {self.config.grasp_service}")
        self._holding, self._held_since = held, time.monotonic()
        if held != name:
            raise StepFailure(f"the gripper closed on {held}, not {name}")
        return Outcome.done(f"holding {name}")

    # -- the rest of the robot interface -------------------------------------------

    def stop(self) -> None:
        with self._publish_lock:
            self._halt()

    def _halt(self) -> None:
        """Abort the step in progress and stop the base; the caller holds the publish lock."""
        self._stops += 1
        self._link.send_zero_twist()
        odom = self._link.odometry()
        if odom is not None:
            self._link.send_goal(odom.pose.x, odom.pose.y, odom.pose.heading)

    def state(self) -> RobotState:
        """Pose from odometry, head from joint states, and as known objects everything the
        robot reports on its objects topic plus what perceiving has seen."""
        odom = self._link.odometry()
        pose = odom.pose if odom is not None else Pose(0.0, 0.0, 0.0)
        joints, _ = self._link.joints()
        report, _ = self._link.objects()
        known = dict(self._known)
        if report is not None:
            known.update(report.objects)
        return RobotState(
            pose=pose,
            head_pan=joints.get(self.config.head_pan_joint, 0.0),
            head_tilt=joints.get(self.config.head_tilt_joint, 0.0),
            holding=self._holding_now(),
            known_objects=tuple((n, x, y) for n, (x, y) in sorted(known.items())),
        )

    def close(self) -> None:
        if self._closed:
            return
        with self._publish_lock:
            self._closed = True
            self._halt()
        # Give DDS a moment to deliver the zero Twist before the participant goes away.
        time.sleep(0.05)
        with self._publish_lock:
            self._link.close()

    def __enter__(self) -> Ros2Robot:
        return self

    def __exit__(self, *_exc: object) -> None:
        self.close()

    # -- internals -------------------------------------------------------------------

    def _guarded(self, cancel: CancelToken | None, body: Callable[[CancelToken], Outcome]) -> Outcome:
        """Run one step so that it always returns an Outcome and always leaves the base stopped."""
        token = cancel or CancelToken()
        if self._closed:
            return Outcome.failed("the ROS 2 backend is closed")
        generation = self._stops
        self._generation = generation
        try:
            if token.is_set():
                return Outcome.cancelled(token.reason)
            self._link.await_bumper_quiet(BUMPER_QUIET, BUMPER_QUIET_LIMIT)
            return body(token)
        except _Cancelled as exc:
            return Outcome.cancelled(str(exc))
        except (StepFailure, BindingFailure, ServiceError, FormatError) as exc:
            return Outcome.failed(str(exc))
        except Exception as exc:  # the robot must stop whatever went wrong
            return Outcome.failed(f"internal error in the ROS 2 backend: {type(exc).__name__}: {exc}")
        finally:
            with self._publish_lock:
                self._link.send_zero_twist()

    def _drive(self, distance: float, direction: float, token: CancelToken, what: str) -> Outcome:
        start = self._fresh_odometry().pose
        ux, uy = math.cos(start.heading), math.sin(start.heading)

        def progress(pose: Pose) -> float:
            return direction * ((pose.x - start.x) * ux + (pose.y - start.y) * uy)

        def command(speed: float, pose: Pose) -> tuple[float, float]:
            # Hold the start heading so a long drive stays straight.
            hold = max(-0.2, min(0.2, 2.0 * wrap_angle(start.heading - pose.heading)))
            return direction * speed, hold

        budget = move_budget(distance, self._linear.max_speed, self._linear.max_accel,
                             self.profile.motion.timeout_margin)
        self._control(distance, progress, command, self._linear, LINEAR_TOLERANCE, budget, token, what)
        return Outcome.done()

    def _turn(self, angle: float, direction: float, token: CancelToken, what: str) -> Outcome:
        last = [self._fresh_odometry().pose.heading]
        turned = [0.0]

        def progress(pose: Pose) -> float:
            # Accumulate small increments so turns of several full circles count right.
            turned[0] += wrap_angle(pose.heading - last[0])
            last[0] = pose.heading
            return direction * turned[0]

        def command(speed: float, _pose: Pose) -> tuple[float, float]:
            return 0.0, direction * speed

        budget = move_budget(angle, self._angular.max_speed, self._angular.max_accel,
                             self.profile.motion.timeout_margin)
        self._control(angle, progress, command, self._angular, ANGULAR_TOLERANCE, budget, token, what)
        return Outcome.done()

    def _control(self, amount: float, progress: Callable[[Pose], float],
                 command: Callable[[float, Pose], tuple[float, float]], limits: Limits,
                 tolerance: float, budget: float, token: CancelToken, what: str) -> None:
        self._require_listener(lambda: self._link.listeners("cmd_vel"), self.config.cmd_vel)
        started = time.monotonic()
        deadline = started + budget
        speed = 0.0
        while True:
            odom = self._fresh_odometry()
            remaining = amount - progress(odom.pose)
            self._check_interrupts(token)
            self._check_bumper(started, what)
            if time.monotonic() > deadline:
                raise StepFailure(f"{what} timed out after {budget:.1f} s with {abs(remaining):.3f} "
                                  "still to go; the base was stopped. Is something blocking the robot?")
            if abs(remaining) <= tolerance:
                # Done only once the base stands still inside the tolerance: a late
                # odometry message or a slow brake can carry it out again, and then
                # the loop drives back.
                if abs(odom.linear) < STILL_LINEAR and abs(odom.angular) < STILL_ANGULAR:
                    return
                speed, (linear, angular) = 0.0, (0.0, 0.0)
            else:
                speed = next_speed(remaining, speed, limits, CONTROL_PERIOD)
                linear, angular = command(speed, odom.pose)
            with self._publish_lock:
                self._check_interrupts(token)
                self._link.send_twist(linear, angular)
            token.wait(CONTROL_PERIOD)

    def _drive_to_goal(self, x: float, y: float, heading: float, token: CancelToken) -> None:
        """Send a goal pose and wait until odometry shows the base there and still; the
        heading is a hint for the navigation stack, not part of arriving."""
        self._require_listener(lambda: self._link.listeners("goal"), self.config.goal_pose)
        start = self._fresh_odometry().pose
        far = math.hypot(x - start.x, y - start.y)
        turning = abs(wrap_angle(math.atan2(y - start.y, x - start.x) - start.heading)) + math.pi
        motion = self.profile.motion
        budget = (move_budget(far, motion.max_linear_speed, motion.max_linear_accel, motion.timeout_margin)
                  + turning / motion.max_angular_speed)
        started = time.monotonic()
        deadline = started + budget
        with self._publish_lock:
            self._check_interrupts(token)
            self._link.send_goal(x, y, heading)
        reached = moved = False
        still_since = math.inf
        tolerance = self.config.goal_tolerance
        try:
            while True:
                self._check_interrupts(token)
                self._check_bumper(started, f"the drive to ({x:.2f}, {y:.2f})")
                odom = self._fresh_odometry()
                now = time.monotonic()
                off = math.hypot(x - odom.pose.x, y - odom.pose.y)
                turned = abs(wrap_angle(heading - odom.pose.heading))
                still = abs(odom.linear) < STILL_LINEAR and abs(odom.angular) < STILL_ANGULAR
                if off <= tolerance and still:
                    reached = True
                    return
                moved = moved or not still
                still_since = min(still_since, now) if still else math.inf
                if moved and now - still_since > GOAL_GIVE_UP:
                    # The navigation stack has settled short of the goal: say so now
                    # rather than at the timeout.
                    raise StepFailure(f"the robot stopped {off:.2f} m from ({x:.2f}, {y:.2f}), "
                                      f"{math.degrees(turned):.0f} degrees off the goal heading; the goal "
                                      f"tolerance is {tolerance:g} m. Is the path blocked, or is the "
                                      "navigation stack's own goal tolerance larger than the profile's "
                                      "[ros] goal_tolerance?")
                if now > deadline:
                    raise StepFailure(f"did not reach ({x:.2f}, {y:.2f}) within {budget:.1f} s; "
                                      f"stopped {off:.2f} m from it. Is the path blocked?")
                token.wait(CONTROL_PERIOD)
        finally:
            if not reached:
                self._cancel_goal()

    def _cancel_goal(self) -> None:
        # A goal at the current pose is how a plain goal_pose follower is told to stop;
        # the zero Twist that follows covers drivers that let cmd_vel override goals.
        with self._publish_lock:
            odom = self._link.odometry()
            if odom is not None:
                self._link.send_goal(odom.pose.x, odom.pose.y, odom.pose.heading)
            self._link.send_zero_twist()

    def _look(self, pan_by: float, tilt_by: float, token: CancelToken) -> Outcome:
        pan_joint, tilt_joint = self.config.head_pan_joint, self.config.head_tilt_joint
        joints = self._fresh_joints([pan_joint, tilt_joint])
        notes = []
        targets = []
        for joint, now, by in (("pan", joints[pan_joint], pan_by), ("tilt", joints[tilt_joint], tilt_by)):
            low, high = self.profile.head[joint]
            wanted = now + by
            target = min(max(wanted, low), high)
            if by and abs(target - wanted) > 1e-9:
                notes.append(f"{joint} limited to {target:g} rad, its joint limit")
            targets.append(target)
        pan, tilt = targets
        travel = max(abs(pan - joints[pan_joint]), abs(tilt - joints[tilt_joint]))
        duration = travel / self.profile.motion.max_head_speed
        self._require_listener(lambda: self._link.listeners("head"),
                               self.config.head_trajectory)
        self._link.send_head(pan, tilt, duration)
        try:
            self._await_joints({pan_joint: pan, tilt_joint: tilt}, duration, token, "head")
        except _Cancelled:
            # Hold the head where it is rather than letting it finish the cancelled move.
            positions, _ = self._link.joints()
            with self._publish_lock:
                self._link.send_head(positions[pan_joint], positions[tilt_joint], 0.0)
            raise
        return Outcome.done("; ".join(notes))

    def _move_gripper(self, position: float, token: CancelToken) -> None:
        joint = self.config.gripper_joint
        now = self._fresh_joints([joint])[joint]
        if abs(now - position) <= JOINT_TOLERANCE:
            return
        self._require_listener(lambda: self._link.listeners("gripper"),
                               self.config.gripper_trajectory)
        self._link.send_gripper(position, 0.5)
        self._await_joints({joint: position}, 0.5, token, "gripper")

    def _await_joints(self, targets: dict[str, float], duration: float, token: CancelToken,
                      what: str) -> None:
        budget = 1.5 * duration + 1.0 + self.profile.motion.timeout_margin
        deadline = time.monotonic() + budget
        while True:
            joints = self._fresh_joints(list(targets))
            if all(abs(joints[j] - t) <= JOINT_TOLERANCE for j, t in targets.items()):
                return
            self._check_interrupts(token)
            if time.monotonic() > deadline:
                where = ", ".join(f"{j} at {joints[j]:.3f} (wanted {t:.3f})" for j, t in targets.items())
                raise StepFailure(f"the {what} did not reach its target within {budget:.1f} s: {where}")
            token.wait(CONTROL_PERIOD)

    def _fresh_odometry(self) -> Odometry:
        odom = self._link.odometry()
        limit = self.config.odom_timeout
        age = math.inf if odom is None else time.monotonic() - odom.received
        if odom is None or age > limit:
            with self._publish_lock:
                self._link.send_zero_twist()
            seen = "never arrived" if odom is None else f"last arrived {age:.2f} s ago"
            raise StepFailure(f"odometry on {self.config.odom} is stale ({seen}, limit {limit:g} s); "
                              "the base was stopped. Check the robot's driver and the network link.")
        assert odom is not None
        return odom

    def _fresh_joints(self, names: list[str]) -> dict[str, float]:
        joints, received = self._link.joints()
        missing = [n for n in names if n not in joints]
        deadline = time.monotonic() + FIRST_MESSAGE_WAIT
        while missing and time.monotonic() < deadline:
            # Just connected: joint states repeat, so the first one is near.
            time.sleep(0.02)
            joints, received = self._link.joints()
            missing = [n for n in names if n not in joints]
        if missing:
            raise StepFailure(f"no position for joint(s) {', '.join(missing)} on {self.config.joint_states}; "
                              "check the joint names in the profile's [ros] table and that the "
                              "joint state publisher runs")
        age = time.monotonic() - received
        if age > max(1.0, 2 * self.config.odom_timeout):
            raise StepFailure(f"joint states on {self.config.joint_states} are stale "
                              f"(last arrived {age:.2f} s ago)")
        return {n: joints[n] for n in names}

    def _check_interrupts(self, token: CancelToken) -> None:
        if token.is_set():
            raise _Cancelled(token.reason or "cancelled")
        if self._stops != self._generation:
            raise _Cancelled("emergency stop")

    def _check_bumper(self, since: float, what: str) -> None:
        stop = self._link.bumper_stop(since)
        if stop is not None:
            raise StepFailure(_bumped(what, stop))

    def _require_listener(self, count: Callable[[], int], topic: str) -> None:
        if not self._link.await_subscriber(count):
            raise StepFailure(f"nobody subscribes to {topic}: the robot would not receive the command. "
                              "Is its controller running and is the topic name in the profile right?")

    def _object_position(self, name: str, token: CancelToken) -> tuple[float, float]:
        found, error = self._lookup_object(name)
        if found is not None:
            return found
        if error:
            return self._unknown_object(name)
        # Look before refusing, as the simulator does: a person who asks for the
        # cup expects the robot to use its camera if the cup is in view.
        reply = self._link.call_perceive(token)
        if reply.success:
            report = decode_objects(reply.message, f"reply of {self.config.perceive_service}")
            self._known.update(report.objects)
            self._footprints.update(report.footprints)
            if name in self._known:
                return self._known[name]
        return self._unknown_object(name)

    def _lookup_object(self, name: str) -> tuple[tuple[float, float] | None, str | None]:
        report, error = self._link.objects()
        deadline = time.monotonic() + FIRST_MESSAGE_WAIT
        while report is None and not error and name not in self._known and time.monotonic() < deadline:
            # Just connected: the objects topic repeats, so its next message is near.
            time.sleep(0.05)
            report, error = self._link.objects()
        if report is not None and name in report.objects:
            return report.objects[name], None
        return self._known.get(name), error

    def _unknown_object(self, name: str) -> tuple[float, float]:
        report, error = self._link.objects()
        known = sorted(set(self._known) | set(report.objects if report else ()))
        hint = f"known objects: {', '.join(known)}" if known else "no objects are known yet"
        extra = f" (the objects topic sent malformed data: {error})" if error else ""
        raise StepFailure(f"unknown object `{name}`: the robot has not seen it and cannot see it from here "
                          f"({hint}{extra}); turn towards it or look around first")

    def _edge(self, name: str, direction: float) -> float:
        """How far the object's edge is from its centre, seen from `direction`; 0 if unknown."""
        report, _ = self._link.objects()
        footprint = report.footprints.get(name) if report is not None else None
        footprint = footprint or self._footprints.get(name)
        if footprint is None:
            return 0.0
        return footprint_radius(footprint.shape, footprint.size, footprint.yaw, direction)

    def _check_nearest(self, name: str, away: float, here: Pose) -> None:
        report, _ = self._link.objects()
        if report is None:
            return
        for other, (x, y) in report.objects.items():
            if other != name and other != report.held and math.hypot(x - here.x, y - here.y) < away:
                raise StepFailure(f"{other} is nearer to the gripper than {name}, so the grasp would "
                                  f"take {other}; {approach_first(self.profile, name)}")

    def _check_workspace(self, x: float, y: float, what: str) -> None:
        (xlo, xhi), (ylo, yhi) = self.profile.workspace["x"], self.profile.workspace["y"]
        if not (xlo <= x <= xhi and ylo <= y <= yhi):
            raise StepFailure(f"{what} is at ({x:.2f}, {y:.2f}), outside the workspace "
                              f"x {xlo:g}..{xhi:g}, y {ylo:g}..{yhi:g}")

    def _holding_now(self) -> str | None:
        report, _ = self._link.objects()
        received = self._link.objects_received()
        if report is not None and received > self._held_since:
            return report.held
        return self._holding


def _bumped(what: str, stop: BumperStop) -> str:
    it = f"the {stop.obstacle}" if stop.obstacle else "it"
    obstacle = it if stop.obstacle else "an obstacle"
    at = f", at ({stop.point[0]:.2f}, {stop.point[1]:.2f}) against the base" if stop.point else ""
    return (f"{what} stopped: {obstacle} is in the way{at}; the bumper stopped the base before it pushed "
            f"{it}. Go around {it} or back away from it first.")


class _Cancelled(Exception):
    """Ends a step with a cancelled outcome; the message is the reason."""
