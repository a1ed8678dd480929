"""Entry point of gift_sim_drake: the robots ``franka`` and ``jaco``, one simulator ``drake-<robot>`` per
registered robot (this package's and any other plugin's), and the Drake motions of the four task
families (``drake/<family>``).

Drake is imported only when a simulator is built, so ``gift plugins`` stays fast. The four task
families themselves live in the core (:mod:`gift.tasks`), so suites load without any simulator.
"""

from __future__ import annotations

import functools

from gift.plugins.hookspecs import hookimpl

#: The families of :mod:`gift_sim_drake.tabletop`, registered as ``drake/<family>``.
TABLETOP_FAMILIES = ("pack_backpack", "store_drawer", "sweep_spill", "place_mug")


def drake_simulator(robot: str, render_cache_dir: str | None = None):
    """A :class:`gift_sim_drake.simulator.DrakeSimulator` of ``robot`` (renders cached in ``render_cache_dir``,
    default ``$GIFT_CACHE_DIR/renders``)."""
    from gift_sim_drake.simulator import DrakeSimulator

    return DrakeSimulator(robot, render_cache_dir=render_cache_dir)


def tabletop_family(task: str):
    """The :class:`~gift_sim_drake.families.MotionFamily` of one of the paper's four families."""
    from gift_sim_drake.tabletop import FAMILIES

    return FAMILIES[task]()


@hookimpl
def gift_register_doctor_checks(register):
    from gift_sim_drake import doctor

    register("drake", doctor.check_drake, description="pydrake imports")
    register("EGL", doctor.check_egl, description="EGL libraries for Drake's headless renders")
    register("robots", doctor.check_robots, description="every registered robot's URDF chain and rest posture")


@hookimpl
def gift_register_robots(register):
    from gift_sim_drake.robots import ROBOTS  # numpy and the URDF reader only; no Drake

    for spec in ROBOTS.values():
        register(spec)  # under spec.name


@hookimpl
def gift_register_robot_simulators(register, robot):
    from gift_sim_drake.robots import simulator_name

    register(simulator_name(robot.name), functools.partial(drake_simulator, robot.name),
             description=f"{robot.description or robot.name} on a Drake MultibodyPlant: the task families, "
                         f"features, renders")


@hookimpl
def gift_register_motions(register):
    for task in TABLETOP_FAMILIES:
        register(f"drake/{task}", functools.partial(tabletop_family, task),
                 description=f"Drake scenes and pick/push/carry actions of {task}")
