"""Entry point of gift_sim_drake: registers the simulators ``drake-franka`` and ``drake-jaco``.

Drake is imported only when a simulator is built, so ``gift plugins`` stays fast. The four task
families themselves live in the core (:mod:`gift.tasks`), so suites load without any simulator.
"""

from __future__ import annotations

from gift.plugins.hookspecs import hookimpl


def drake_franka(**options):
    """Franka Panda (7-DoF) on a Drake MultibodyPlant: the four task families, features, renders."""
    from gift_sim_drake.simulator import DrakeFranka

    return DrakeFranka(**options)


def drake_jaco(**options):
    """Kinova Jaco2 7-DoF (j2s7s300) on a Drake MultibodyPlant: the four task families, features, renders."""
    from gift_sim_drake.simulator import DrakeJaco

    return DrakeJaco(**options)


@hookimpl
def gift_register_doctor_checks(register):
    from gift_sim_drake import doctor

    register("drake", doctor.check_drake, description="pydrake imports")
    register("EGL", doctor.check_egl, description="EGL libraries for Drake's headless renders")


@hookimpl
def gift_register_simulators(register):
    register("drake-franka", drake_franka, description=drake_franka.__doc__.splitlines()[0])
    register("drake-jaco", drake_jaco, description=drake_jaco.__doc__.splitlines()[0])
