"""Skills bound to ROS 2 in the profile: a topic publish, a std_srvs call or a joint trajectory.

Everything is made when the backend starts, so discovery runs in the
background and a message type or field the profile names wrongly is a
`ProfileError` at start-up, not a failure halfway through a plan. The
conventions followed (docs/skills.md):
- `topic`: any message type, fields set from the statement's parameters;
- `trigger` / `setbool`: std_srvs/srv/Trigger and SetBool; `success = false`
  fails the step with the service's message;
- `joint_trajectory`: one trajectory_msgs/msg/JointTrajectory point on a
  controller's `joint_trajectory` topic, as ros2_control's
  joint_trajectory_controller (the FollowJointTrajectory controller) takes it.
"""

from __future__ import annotations

import importlib
import time
from typing import Any

from agent.robot import CancelToken, Outcome
from agent.ros2.link import RobotLink
from rsl.profile import Param, Profile, ProfileError, RosBinding, Source

JOINT_TOLERANCE = 0.01  # rad (or m): a joint this close to its target has arrived
CONTROL_PERIOD = 0.02  # s between checks of the joint states


class BindingFailure(Exception):
    """Ends a step with a failed outcome; the message is the reason."""


class BoundSkills:
    def __init__(self, link: RobotLink, profile: Profile) -> None:
        from std_srvs.srv import SetBool, Trigger
        from trajectory_msgs.msg import JointTrajectory

        self._link = link
        self._margin = profile.motion.timeout_margin
        self._channels: dict[str, Any] = {}
        self._types: dict[str, Any] = {}
        self._set_bool = SetBool.Request
        for skill in profile.skills:
            binding = skill.binding
            if not isinstance(binding, RosBinding):
                continue
            where = f"{profile.source or profile.name}: skill `{skill.keyword}`"
            if binding.kind == "topic":
                message = _message_type(binding.message_type, where)
                for path, _source in binding.fields:
                    _check_field(message(), path, f"{where}: {binding.message_type}")
                self._types[skill.keyword] = message
                self._channels[skill.keyword] = link.publisher(message, binding.name)
            elif binding.kind == "joint_trajectory":
                self._channels[skill.keyword] = link.publisher(JointTrajectory, binding.name)
            else:
                service = Trigger if binding.kind == "trigger" else SetBool
                self._channels[skill.keyword] = link.client(service, binding.name)

    def perform(self, keyword: str, binding: RosBinding, params: tuple[Param, ...],
                args: tuple[float | str, ...], token: CancelToken) -> Outcome:
        values = {p.name: a for p, a in zip(params, args, strict=True)}

        def value(source: Source) -> Any:
            return values[source] if isinstance(source, str) else source

        channel = self._channels[keyword]
        if binding.kind == "topic":
            self._await_listener(channel, binding.name)
            message = self._types[keyword]()
            for path, source in binding.fields:
                _set_field(message, path, value(source))
            channel.publish(message)
            return Outcome.done(f"published on {binding.name}")
        if binding.kind in ("trigger", "setbool"):
            request = None
            if binding.kind == "setbool":
                request = self._set_bool()
                request.data = bool(binding.data)
            reply = self._link.call(channel, binding.name, token, request)
            if not reply.success:
                raise BindingFailure(f"{binding.name} refused: {reply.message or 'no reason given'}")
            return Outcome.done(f"{binding.name}: {reply.message}" if reply.message else "")
        positions = [float(value(p)) for p in binding.positions]
        self._await_listener(channel, binding.name)
        self._link.send_trajectory(channel, list(binding.joints), positions, binding.duration)
        return self._await_joints(dict(zip(binding.joints, positions, strict=True)), binding.duration, token)

    def _await_listener(self, publisher: Any, topic: str) -> None:
        if not self._link.await_subscriber(publisher.get_subscription_count):
            raise BindingFailure(f"nobody subscribes to {topic}: the robot would not receive the command. "
                                 "Is its controller running and is the name in the skill's binding right?")

    def _await_joints(self, targets: dict[str, float], duration: float, token: CancelToken) -> Outcome:
        """Wait for the joints to arrive when joint_states reports them; otherwise for the duration."""
        joints, _ = self._link.joints()
        if any(name not in joints for name in targets):
            if token.wait(duration):
                return Outcome.cancelled(token.reason or "cancelled")
            return Outcome.done(f"sent; arrival not checked, joint_states does not report "
                                f"{', '.join(n for n in targets if n not in joints)}")
        deadline = time.monotonic() + 1.5 * duration + 1.0 + self._margin
        while True:
            joints, _ = self._link.joints()
            if all(abs(joints[n] - t) <= JOINT_TOLERANCE for n, t in targets.items()):
                return Outcome.done()
            if token.is_set():
                return Outcome.cancelled(token.reason or "cancelled")
            if time.monotonic() > deadline:
                where = ", ".join(f"{n} at {joints[n]:.3f} (wanted {t:.3f})" for n, t in targets.items())
                raise BindingFailure(f"the joints did not reach their target in time: {where}")
            token.wait(CONTROL_PERIOD)


def _message_type(name: str, where: str) -> Any:
    package, _msg, cls = name.split("/")
    try:
        return getattr(importlib.import_module(f"{package}.msg"), cls)
    except (ImportError, AttributeError):
        raise ProfileError(f"{where}: message type {name} is not installed here; "
                           "check the name or install its package") from None


def _check_field(message: Any, path: str, where: str) -> None:
    target = message
    for part in path.split("."):
        if part not in getattr(target, "get_fields_and_field_types", dict)():
            raise ProfileError(f"{where} has no field `{path}`")
        target = getattr(target, part)


def _set_field(message: Any, path: str, value: Any) -> None:
    *parents, last = path.split(".")
    for part in parents:
        message = getattr(message, part)
    current = getattr(message, last)
    # Convert to the field's own type: a parameter is a float, a field may be an int or a string.
    kind = type(current)
    setattr(message, last, kind(value) if kind in (bool, int, float, str) else value)
