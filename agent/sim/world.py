"""Low-level physics of the simulated robot: a pybullet world, no control loops.

The robot is a small mobile manipulator built from a URDF generated here, so
its head limits come from the robot profile (the one source of truth):

- a box base on wheels, driven as a differential drive: the world applies the
  commanded body-frame (linear, angular) velocity every physics step, changing
  it no faster than the motors can (`MOTOR_ACCEL`), so even an emergency stop
  takes a few physics steps, as on a real base;
- a mast with a pan-tilt head and a camera (position-controlled joints that
  move no faster than `profile.motion.max_head_speed`);
- a fixed arm with a two-finger gripper at `GRIPPER_HEIGHT`; `grasp` pulls an
  object in reach to the gripper with a force-limited constraint.

Everything runs headless in pybullet's DIRECT mode, one client per world, so
several worlds can live in one process.
"""

from __future__ import annotations

import math
import os
import sys
import tempfile
import time
from collections import deque
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass

import numpy as np
import pybullet
import pybullet_data
from pybullet_utils.bullet_client import BulletClient

from agent.robot import Outcome, Pose
from agent.sim.scene import Scene, SceneObject, load_scene
from rsl.profile import Profile

PHYSICS_HZ = 120
MOTOR_ACCEL = (4.0, 8.0)  # m/s^2 and rad/s^2 the wheels can change speed at, braking included
BASE_SIZE = (0.5, 0.4, 0.3)
MAST_HEIGHT = 0.8
GRIPPER_HEIGHT = 0.9  # m above the floor
GRIPPER_FORWARD = 0.38  # m ahead of the base centre
CAMERA_HFOV = math.radians(80.0)
CAMERA_VFOV = math.radians(60.0)
CAMERA_RANGE = 8.0  # m
GRASP_BEARING = math.radians(60.0)  # the gripper only reaches objects roughly in front
GRASP_FORCE = 60.0  # N, so a pinned object resists instead of teleporting
TRAJECTORY_LIMIT = PHYSICS_HZ * 600  # samples kept: ten minutes, so a long-running bridge does not grow


@dataclass(frozen=True)
class Sample:
    """The robot's state after one physics step; the trajectory is a list of these."""

    sim_time: float
    wall_time: float
    x: float
    y: float
    heading: float
    linear: float
    angular: float
    pan: float
    tilt: float


def _robot_urdf(profile: Profile) -> str:
    pan_lo, pan_hi = profile.head["pan"]
    tilt_lo, tilt_hi = profile.head["tilt"]
    bx, by, bz = BASE_SIZE
    wheel = """
  <link name="{name}">
    <visual><origin rpy="1.5708 0 0"/><geometry><cylinder radius="0.1" length="0.05"/></geometry>
      <material name="black"><color rgba="0.1 0.1 0.1 1"/></material></visual>
    <inertial><mass value="0.5"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>
  </link>
  <joint name="{name}_joint" type="fixed"><parent link="base_link"/><child link="{name}"/>
    <origin xyz="{x} {y} {z}"/></joint>"""
    wheels = "".join(
        wheel.format(name=f"wheel_{i}", x=sx * (bx / 2 - 0.1), y=sy * (by / 2 + 0.03), z=-bz / 2 + 0.1)
        for i, (sx, sy) in enumerate(((1, 1), (1, -1), (-1, 1), (-1, -1)))
    )
    arm_z = GRIPPER_HEIGHT - bz / 2
    return f"""<?xml version="1.0"?>
<robot name="nrtrans_sim">
  <link name="base_link">
    <visual><geometry><box size="{bx} {by} {bz}"/></geometry>
      <material name="grey"><color rgba="0.35 0.38 0.45 1"/></material></visual>
    <collision><geometry><box size="{bx} {by} {bz}"/></geometry></collision>
    <inertial><mass value="30"/><inertia ixx="0.6" iyy="0.8" izz="1.0" ixy="0" ixz="0" iyz="0"/></inertial>
  </link>{wheels}
  <link name="mast">
    <visual><origin xyz="0 0 {MAST_HEIGHT / 2}"/><geometry><cylinder radius="0.03" length="{MAST_HEIGHT}"/>
      </geometry><material name="steel"><color rgba="0.7 0.7 0.75 1"/></material></visual>
    <inertial><mass value="1"/><inertia ixx="0.05" iyy="0.05" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>
  </link>
  <joint name="mast_joint" type="fixed"><parent link="base_link"/><child link="mast"/>
    <origin xyz="-0.1 0 {bz / 2}"/></joint>
  <link name="head_pan_link">
    <visual><geometry><cylinder radius="0.05" length="0.06"/></geometry>
      <material name="steel"/></visual>
    <inertial><mass value="0.3"/><inertia ixx="0.001" iyy="0.001" izz="0.001" ixy="0" ixz="0" iyz="0"/></inertial>
  </link>
  <joint name="head_pan_joint" type="revolute"><parent link="mast"/><child link="head_pan_link"/>
    <origin xyz="0 0 {MAST_HEIGHT + 0.03}"/><axis xyz="0 0 1"/>
    <limit lower="{pan_lo}" upper="{pan_hi}" effort="20" velocity="{profile.motion.max_head_speed}"/>
  </joint>
  <link name="head_tilt_link">
    <visual><geometry><box size="0.12 0.2 0.1"/></geometry>
      <material name="white"><color rgba="0.9 0.9 0.9 1"/></material></visual>
    <inertial><mass value="0.3"/><inertia ixx="0.001" iyy="0.001" izz="0.001" ixy="0" ixz="0" iyz="0"/></inertial>
  </link>
  <joint name="head_tilt_joint" type="revolute"><parent link="head_pan_link"/><child link="head_tilt_link"/>
    <origin xyz="0 0 0.08"/><axis xyz="0 -1 0"/>
    <limit lower="{tilt_lo}" upper="{tilt_hi}" effort="20" velocity="{profile.motion.max_head_speed}"/>
  </joint>
  <link name="camera_link">
    <visual><origin rpy="0 1.5708 0"/><geometry><cylinder radius="0.03" length="0.03"/></geometry>
      <material name="black"/></visual>
    <inertial><mass value="0.05"/><inertia ixx="0.0001" iyy="0.0001" izz="0.0001" ixy="0" ixz="0" iyz="0"/>
    </inertial>
  </link>
  <joint name="camera_joint" type="fixed"><parent link="head_tilt_link"/><child link="camera_link"/>
    <origin xyz="0.075 0 0"/></joint>
  <link name="arm">
    <visual><origin xyz="{(GRIPPER_FORWARD - 0.06) / 2} 0 0"/>
      <geometry><box size="{GRIPPER_FORWARD - 0.06} 0.05 0.05"/></geometry><material name="steel"/></visual>
    <inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>
  </link>
  <joint name="arm_joint" type="fixed"><parent link="base_link"/><child link="arm"/>
    <origin xyz="0 0 {arm_z}"/></joint>
  <link name="gripper_left">
    <visual><origin xyz="0.04 0 0"/><geometry><box size="0.08 0.015 0.04"/></geometry>
      <material name="orange"><color rgba="0.95 0.55 0.1 1"/></material></visual>
    <inertial><mass value="0.1"/><inertia ixx="0.0001" iyy="0.0001" izz="0.0001" ixy="0" ixz="0" iyz="0"/>
    </inertial>
  </link>
  <joint name="gripper_joint" type="prismatic"><parent link="arm"/><child link="gripper_left"/>
    <origin xyz="{GRIPPER_FORWARD - 0.06} 0 0"/><axis xyz="0 1 0"/>
    <limit lower="0.0" upper="0.06" effort="40" velocity="0.2"/></joint>
  <link name="gripper_right">
    <visual><origin xyz="0.04 0 0"/><geometry><box size="0.08 0.015 0.04"/></geometry>
      <material name="orange"/></visual>
    <inertial><mass value="0.1"/><inertia ixx="0.0001" iyy="0.0001" izz="0.0001" ixy="0" ixz="0" iyz="0"/>
    </inertial>
  </link>
  <joint name="gripper_right_joint" type="prismatic"><parent link="arm"/><child link="gripper_right"/>
    <origin xyz="{GRIPPER_FORWARD - 0.06} 0 0"/><axis xyz="0 -1 0"/>
    <limit lower="0.0" upper="0.06" effort="40" velocity="0.2"/></joint>
</robot>
"""


@contextmanager
def _stdout_to_stderr() -> Iterator[None]:
    """pybullet's C code prints a banner on connect; keep it off stdout, which may carry JSON."""
    sys.stdout.flush()
    saved = os.dup(1)
    try:
        os.dup2(2, 1)
        yield
    finally:
        os.dup2(saved, 1)
        os.close(saved)


def _wrap(angle: float) -> float:
    return (angle + math.pi) % (2.0 * math.pi) - math.pi


class SimWorld:
    """One pybullet world with the robot and the scene's objects in it."""

    def __init__(self, profile: Profile, scene: Scene | None = None, *, realtime_factor: float = 0.0):
        if realtime_factor < 0:
            raise ValueError(f"realtime_factor must be 0 (as fast as possible) or positive, got {realtime_factor}")
        self.profile = profile
        self.scene = scene if scene is not None else load_scene()
        self.realtime_factor = realtime_factor
        self.dt = 1.0 / PHYSICS_HZ
        self.sim_time = 0.0
        self.holding: str | None = None
        self.trajectory: deque[Sample] = deque(maxlen=TRAJECTORY_LIMIT)
        self._listeners: list[Callable[[SimWorld], None]] = []
        self._command = (0.0, 0.0)
        self._pose: Pose | None = None
        self._velocity = (0.0, 0.0)
        self._head_target = (0.0, 0.0)
        self._grip_constraint: int | None = None
        self._wall_start = time.monotonic()
        with _stdout_to_stderr():
            self._client = BulletClient(connection_mode=pybullet.DIRECT)
        self._closed = False
        client = self._client
        client.setAdditionalSearchPath(pybullet_data.getDataPath())
        client.setGravity(0, 0, -9.81)
        client.setTimeStep(self.dt)
        self._floor = client.loadURDF("plane.urdf")
        self._robot = self._load_robot()
        self._bodies: dict[str, int] = {obj.name: self._spawn(obj) for obj in self.scene.objects}
        self._names = {uid: name for name, uid in self._bodies.items()}
        self._log_sample()

    # -- construction -------------------------------------------------------------------------------

    def _load_robot(self) -> int:
        client = self._client
        handle, path = tempfile.mkstemp(suffix=".urdf", prefix="nrtrans_robot_")
        try:
            with os.fdopen(handle, "w") as urdf:
                urdf.write(_robot_urdf(self.profile))
            start = self.scene.start
            robot = client.loadURDF(path, [start.x, start.y, BASE_SIZE[2] / 2 + 0.002],
                                    client.getQuaternionFromEuler([0, 0, start.heading]))
        finally:
            os.unlink(path)
        self._joints = {client.getJointInfo(robot, j)[1].decode(): j for j in range(client.getNumJoints(robot))}
        # The base slides on frictionless wheels: its motion comes only from the
        # commanded velocity, the way a differential drive with good traction behaves.
        client.changeDynamics(robot, -1, lateralFriction=0.0, rollingFriction=0.0, spinningFriction=0.0)
        for joint in self._joints.values():
            client.changeDynamics(robot, joint, lateralFriction=1.0)
        for name in ("gripper_joint", "gripper_right_joint"):
            client.setJointMotorControl2(robot, self._joints[name], pybullet.POSITION_CONTROL,
                                         targetPosition=0.05, force=40)
        return robot

    def _spawn(self, obj: SceneObject) -> int:
        client = self._client
        sx, sy, sz = obj.size
        rgba = [*obj.color, 1.0]
        if obj.shape == "sphere":
            collision = client.createCollisionShape(pybullet.GEOM_SPHERE, radius=sx / 2)
            visual = client.createVisualShape(pybullet.GEOM_SPHERE, radius=sx / 2, rgbaColor=rgba)
        elif obj.shape == "cylinder":
            collision = client.createCollisionShape(pybullet.GEOM_CYLINDER, radius=sx / 2, height=sz)
            visual = client.createVisualShape(pybullet.GEOM_CYLINDER, radius=sx / 2, length=sz, rgbaColor=rgba)
        else:
            half = [sx / 2, sy / 2, sz / 2]
            collision = client.createCollisionShape(pybullet.GEOM_BOX, halfExtents=half)
            visual = client.createVisualShape(pybullet.GEOM_BOX, halfExtents=half, rgbaColor=rgba)
        mass = 0.0 if obj.kind == "fixed" else obj.mass
        uid = client.createMultiBody(mass, collision, visual, [obj.x, obj.y, obj.z],
                                     client.getQuaternionFromEuler([0, 0, obj.yaw]))
        # Objects at rest sleep until something touches them: a fourfold cheaper physics step, and
        # resting objects do not creep.
        client.changeDynamics(uid, -1, lateralFriction=0.9, spinningFriction=0.01, rollingFriction=0.002,
                              activationState=pybullet.ACTIVATION_STATE_ENABLE_SLEEPING)
        return uid

    # -- time ---------------------------------------------------------------------------------------

    def add_listener(self, listener: Callable[[SimWorld], None]) -> None:
        """Call `listener(world)` after every physics step (recorders use this)."""
        self._listeners.append(listener)

    def remove_listener(self, listener: Callable[[SimWorld], None]) -> None:
        if listener in self._listeners:
            self._listeners.remove(listener)

    def step(self, n: int = 1) -> None:
        """Advance the physics by `n` steps of `dt`, sleeping to honour the real-time factor."""
        client = self._client
        for _ in range(n):
            self._apply_base_velocity()
            client.stepSimulation()
            self._pose = None
            self.sim_time += self.dt
            if self.realtime_factor > 0:
                ahead = self._wall_start + self.sim_time / self.realtime_factor - time.monotonic()
                if ahead > 0:
                    time.sleep(ahead)
            self._log_sample()
            for listener in self._listeners:
                listener(self)

    def _apply_base_velocity(self) -> None:
        client = self._client
        (target_v, target_w), (v, w) = self._command, self._velocity
        max_dv, max_dw = MOTOR_ACCEL[0] * self.dt, MOTOR_ACCEL[1] * self.dt
        v += max(-max_dv, min(max_dv, target_v - v))
        w += max(-max_dw, min(max_dw, target_w - w))
        self._velocity = (v, w)
        heading = self.base_pose().heading
        vz = client.getBaseVelocity(self._robot)[0][2]
        client.resetBaseVelocity(self._robot, [v * math.cos(heading), v * math.sin(heading), vz], [0.0, 0.0, w])

    def _log_sample(self) -> None:
        pose = self.base_pose()
        linear, angular = self.base_velocity()
        pan, tilt = self.head()
        self.trajectory.append(Sample(self.sim_time, time.monotonic(), pose.x, pose.y, pose.heading,
                                      linear, angular, pan, tilt))

    @property
    def last(self) -> Sample:
        """The newest sample; safe to read from another thread while a skill runs."""
        return self.trajectory[-1]

    # -- base ---------------------------------------------------------------------------------------

    def set_base_velocity(self, linear: float, angular: float) -> None:
        """Command a body-frame velocity (m/s, rad/s), clamped to the profile's speed limits."""
        motion = self.profile.motion
        self._command = (max(-motion.max_linear_speed, min(motion.max_linear_speed, linear)),
                         max(-motion.max_angular_speed, min(motion.max_angular_speed, angular)))

    def base_pose(self) -> Pose:
        # Cached per physics step: the control loops ask several times between two steps.
        if self._pose is None:
            position, orientation = self._client.getBasePositionAndOrientation(self._robot)
            yaw = self._client.getEulerFromQuaternion(orientation)[2]
            self._pose = Pose(position[0], position[1], yaw)
        return self._pose

    def base_velocity(self) -> tuple[float, float]:
        """Measured (linear, angular) velocity in the body frame."""
        linear, angular = self._client.getBaseVelocity(self._robot)
        heading = self.base_pose().heading
        return linear[0] * math.cos(heading) + linear[1] * math.sin(heading), angular[2]

    # -- head and gripper ---------------------------------------------------------------------------

    def set_head_target(self, pan: float, tilt: float) -> tuple[float, float]:
        """Move the head towards (pan, tilt), clamped to the profile's limits; returns the clamped target."""
        pan = max(self.profile.head["pan"][0], min(self.profile.head["pan"][1], pan))
        tilt = max(self.profile.head["tilt"][0], min(self.profile.head["tilt"][1], tilt))
        speed = self.profile.motion.max_head_speed
        for joint, target in (("head_pan_joint", pan), ("head_tilt_joint", tilt)):
            self._client.setJointMotorControl2(self._robot, self._joints[joint], pybullet.POSITION_CONTROL,
                                               targetPosition=target, maxVelocity=speed, force=20,
                                               positionGain=0.3)
        self._head_target = (pan, tilt)
        return pan, tilt

    @property
    def head_target(self) -> tuple[float, float]:
        return self._head_target

    def head(self) -> tuple[float, float]:
        states = self._client.getJointStates(self._robot, [self._joints["head_pan_joint"],
                                                           self._joints["head_tilt_joint"]])
        return states[0][0], states[1][0]

    def set_gripper(self, closed: bool) -> None:
        opening = 0.0 if closed else 0.05
        for name in ("gripper_joint", "gripper_right_joint"):
            self._client.setJointMotorControl2(self._robot, self._joints[name], pybullet.POSITION_CONTROL,
                                               targetPosition=opening, force=40)

    def gripper_tip(self) -> tuple[float, float, float]:
        pose = self.base_pose()
        return (pose.x + GRIPPER_FORWARD * math.cos(pose.heading),
                pose.y + GRIPPER_FORWARD * math.sin(pose.heading), GRIPPER_HEIGHT)

    # -- objects ------------------------------------------------------------------------------------

    def objects(self) -> dict[str, tuple[float, float, float]]:
        """Ground-truth positions of every named object."""
        positions = {}
        for name, uid in self._bodies.items():
            x, y, z = self._client.getBasePositionAndOrientation(uid)[0]
            positions[name] = (float(x), float(y), float(z))
        return positions

    def camera_pose(self) -> tuple[np.ndarray, np.ndarray]:
        """The camera's position and its rotation matrix (columns: forward, left, up)."""
        state = self._client.getLinkState(self._robot, self._joints["camera_joint"], computeForwardKinematics=True)
        rotation = np.array(self._client.getMatrixFromQuaternion(state[5])).reshape(3, 3)
        return np.array(state[4]), rotation

    def visible_objects(self) -> dict[str, tuple[float, float]]:
        """Named objects now inside the camera's field of view and range, and not hidden behind others."""
        eye, rotation = self.camera_pose()
        candidates: list[tuple[str, np.ndarray]] = []
        for name, position in self.objects().items():
            if name == self.holding:
                continue
            local = rotation.T @ (np.array(position) - eye)
            distance = float(np.linalg.norm(local))
            if local[0] <= 0 or distance > CAMERA_RANGE:
                continue
            if abs(math.atan2(local[1], local[0])) > CAMERA_HFOV / 2:
                continue
            if abs(math.atan2(local[2], local[0])) > CAMERA_VFOV / 2:
                continue
            candidates.append((name, np.array(position)))
        if not candidates:
            return {}
        hits = self._client.rayTestBatch([eye.tolist()] * len(candidates), [p.tolist() for _, p in candidates])
        return {name: (float(position[0]), float(position[1]))
                for (name, position), hit in zip(candidates, hits, strict=True)
                if hit[0] in (-1, self._bodies[name])}

    def grasp(self, name: str) -> Outcome:
        """Pick up `name` if it is graspable, in front and within reach; a failed outcome says why not."""
        obj = self.scene.object(name)
        if obj is None:
            return Outcome.failed(f"there is no `{name}` in the scene; objects here: {', '.join(self.scene.names)}")
        if self.holding == name:
            return Outcome.done(f"already holding the {name}")
        if self.holding is not None:
            return Outcome.failed(f"cannot grasp the {name}: the gripper is already holding the {self.holding}")
        if not obj.graspable:
            return Outcome.failed(f"the {name} is {obj.kind} ({obj.mass:g} kg) and cannot be picked up")
        pose = self.base_pose()
        x, y, _ = self.objects()[name]
        distance = math.hypot(x - pose.x, y - pose.y)
        reach = self.profile.motion.reach
        if distance > reach:
            return Outcome.failed(f"{name} is {distance:.1f} m away, out of reach {reach:.1f} m; "
                                  f"approach it first")
        bearing = _wrap(math.atan2(y - pose.y, x - pose.x) - pose.heading)
        if abs(bearing) > GRASP_BEARING:
            side = "left" if bearing > 0 else "right"
            return Outcome.failed(f"{name} is {math.degrees(abs(bearing)):.0f} degrees to the {side}, "
                                  f"outside the gripper's {math.degrees(GRASP_BEARING):.0f} degrees; "
                                  "turn to face it first")
        return self._pull_into_gripper(name)

    def _pull_into_gripper(self, name: str) -> Outcome:
        client, uid = self._client, self._bodies[name]
        for link in range(-1, client.getNumJoints(self._robot)):
            client.setCollisionFilterPair(self._robot, uid, link, -1, 0)
        self.set_gripper(closed=False)
        constraint = client.createConstraint(self._robot, self._joints["gripper_joint"], uid, -1,
                                             pybullet.JOINT_FIXED, [0, 0, 0], [0.04, -0.03, 0], [0, 0, 0])
        client.changeConstraint(constraint, maxForce=GRASP_FORCE)
        for _ in range(int(2.0 / self.dt)):
            self.step()
            gap = np.linalg.norm(np.array(self.objects()[name]) - np.array(self.gripper_tip()))
            if gap < 0.03:
                break
        else:
            client.removeConstraint(constraint)
            for link in range(-1, client.getNumJoints(self._robot)):
                client.setCollisionFilterPair(self._robot, uid, link, -1, 1)
            return Outcome.failed(f"could not lift the {name}: it is stuck {gap:.2f} m from the gripper")
        self.set_gripper(closed=True)
        self._grip_constraint = constraint
        self.holding = name
        return Outcome.done(f"holding the {name}")

    # -- pictures -----------------------------------------------------------------------------------

    def camera_image(self, width: int = 320, height: int = 240, *,
                     look_at: tuple[float, float, float] | None = None) -> np.ndarray:
        """What the head camera sees now, as an RGB array (TinyRenderer; works headless).

        With `look_at`, the camera is aimed from where it is at that point instead (the pictures
        of a step that acts on an object show the object even when the head looks past it).
        """
        eye, rotation = self.camera_pose()
        forward, up = rotation[:, 0], rotation[:, 2]
        if look_at is not None:
            forward, up = np.asarray(look_at, dtype=float) - eye, np.array([0.0, 0.0, 1.0])
        view = self._client.computeViewMatrix(eye.tolist(), (eye + forward).tolist(), up.tolist())
        projection = self._client.computeProjectionMatrixFOV(math.degrees(CAMERA_VFOV), width / height,
                                                             0.05, CAMERA_RANGE * 2)
        _, _, rgba, _, _ = self._client.getCameraImage(width, height, view, projection,
                                                       renderer=pybullet.ER_TINY_RENDERER)
        return np.asarray(rgba, dtype=np.uint8).reshape(height, width, 4)[:, :, :3]

    def overview_image(self, width: int = 320, height: int = 240, *, distance: float = 5.0,
                       yaw: float = -60.0, pitch: float = -45.0) -> np.ndarray:
        """A third-person view of the robot and what is around it, for animations of a run."""
        pose = self.base_pose()
        view = self._client.computeViewMatrixFromYawPitchRoll([pose.x, pose.y, 0.3], distance, yaw, pitch, 0, 2)
        projection = self._client.computeProjectionMatrixFOV(60.0, width / height, 0.1, 50.0)
        _, _, rgba, _, _ = self._client.getCameraImage(width, height, view, projection,
                                                       renderer=pybullet.ER_TINY_RENDERER)
        return np.asarray(rgba, dtype=np.uint8).reshape(height, width, 4)[:, :, :3]

    def close(self) -> None:
        if not self._closed:
            self._closed = True
            self._client.disconnect()
