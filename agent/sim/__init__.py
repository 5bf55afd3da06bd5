"""The pybullet simulator: a headless mobile manipulator in a scene of named objects.

`scene` reads scene files, `world` holds the physics (no control loops),
`robot` drives the world in closed loop behind the `agent.robot.Robot`
interface.
"""
