"""The UR5e as a :class:`gift.core.robots.RobotSpec`.

The URDF (``urdf/ur5e.urdf``, written from Universal Robots' published DH parameters) has the UR's own
base frame: with every joint at zero the arm points along -x. gift's tabletop lies along +x of the
world, so the mount turns the base by pi about the vertical. The rest posture holds the tool centre
point 0.30 m above the table, 0.35 m in front of the base, gripper pointing down, elbow up.
"""

import math

from gift.core.robots import RobotSpec

UR5E = RobotSpec(
    name="ur5e",
    urdf="urdf/ur5e.urdf",
    package="gift_example_robot",
    base_link="base_link",
    ee_link="tcp",
    rest=(-0.39, -1.98, 2.01, -1.60, -1.57, 0.0),
    mount=(0.0, 0.0, 0.0, 0.0, 0.0, math.pi),
    description="Universal Robots UR5e (6-DoF) with a two-finger gripper",
)
