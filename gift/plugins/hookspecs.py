"""The hooks a gift plugin implements.

A plugin is a module (or object) with functions decorated by :data:`gift.hookimpl`, exposed through
an entry point in the group ``gift``::

    # pyproject.toml of a third-party package
    [project.entry-points.gift]
    my_kernel = "my_package.plugin"

    # my_package/plugin.py
    import gift

    @gift.hookimpl
    def gift_register_kernels(register):
        register("my-kernel", MyKernel, description="cosine of my embeddings")

Every ``gift_register_*`` hook receives a ``register(name, factory, *, description="")`` callable.
``factory`` builds the component (a class or any callable); ``gift.get_kernel("my-kernel", **options)``
calls ``factory(**options)``. A component's name has one source: a class with a ``name`` attribute can
be registered as ``register(MyKernel)``; a name given next to it must equal it, and a component built by
a function must carry the name it was registered under (checked when it is built). Unknown options are
rejected with the valid ones listed. Two plugins registering the same name for the same kind is an
error naming both.
"""

from __future__ import annotations

from typing import Any, Protocol

import pluggy

hookspec = pluggy.HookspecMarker("gift")
hookimpl = pluggy.HookimplMarker("gift")


class Register(Protocol):
    """The ``register`` callable handed to every hook."""

    def __call__(self, name: str, factory: Any, *, description: str = "") -> None: ...


class RegisterCommand(Protocol):
    """``register(name, run, *, help="", configure=None)`` for CLI subcommands.

    ``configure(parser)`` adds arguments to an :class:`argparse.ArgumentParser`; ``run(args)`` executes
    the command and returns an exit code (or None for 0).
    """

    def __call__(self, name: str, run: Any, *, help: str = "", configure: Any = None) -> None: ...


@hookspec
def gift_register_simulators(register: Register) -> None:
    """Register :class:`gift.core.interfaces.Simulator` factories (e.g. ``drake-franka``)."""


@hookspec
def gift_register_robots(register: Register) -> None:
    """Register robot arms: ``register(spec)`` with a :class:`gift.core.robots.RobotSpec` (a URDF shipped in the
    plugin's package, base and end-effector frames, home configuration), under ``spec.name``."""


@hookspec
def gift_register_robot_simulators(register: Register, robot: Any) -> None:
    """Register the simulators built for one robot (a :class:`gift.core.robots.RobotSpec`).

    Called once per registered robot, after every plugin's ``gift_register_robots`` ran (and again for a
    robot registered later), so a simulator plugin supports third-party arms without knowing them:
    gift-sim-drake registers ``drake-<robot.name>`` here. The registrations are of kind ``simulator`` and
    remember the robot (:meth:`gift.plugins.manager.GiftPluginManager.simulators_for_robot`).
    """


@hookspec
def gift_register_motions(register: Register) -> None:
    """Register a simulator plugin's motions for a task family, named ``<simulator plugin>/<task family>``
    (gift-sim-drake reads ``drake/<family>``: a :class:`gift_sim_drake.families.MotionFamily` factory giving
    the family's scene layout and candidate actions). The factory's interface is the simulator plugin's."""


@hookspec
def gift_register_tasks(register: Register) -> None:
    """Register :class:`gift.core.interfaces.Task` factories (task families such as ``pack_backpack``)."""


@hookspec
def gift_register_kernels(register: Register) -> None:
    """Register :class:`gift.core.interfaces.SimilarityKernel` factories (``language``, ``gift``, ...)."""


@hookspec
def gift_register_intent_estimators(register: Register) -> None:
    """Register :class:`gift.core.interfaces.IntentEstimator` factories (``lm-contrastive``, ...)."""


@hookspec
def gift_register_alignment_operators(register: Register) -> None:
    """Register :class:`gift.core.interfaces.AlignmentOperator` factories."""


@hookspec
def gift_register_query_policies(register: Register) -> None:
    """Register :class:`gift.core.interfaces.QueryPolicy` factories: which test object to ask the human
    about next (``uncertainty``, ``disagreement``, ``error-bound``, ``expected-error``, ``random``;
    :mod:`gift.core.queries`)."""


@hookspec
def gift_register_reward_models(register: Register) -> None:
    """Register :class:`gift.core.interfaces.RewardModel` factories (``maxent-linear``, ...)."""


@hookspec
def gift_register_lm_backends(register: Register) -> None:
    """Register :class:`gift.core.interfaces.LMBackend` factories (``llamacpp``, ``litellm``, ...)."""


@hookspec(firstresult=True)
def gift_resolve_lm(spec: str | None, options: dict) -> Any:
    """Build the LM for ``spec`` (None: the default; ``"backend:model"``; a registered backend name) with
    ``options``, wrapped as the plugin sees fit (cache, recording). The first plugin that returns an
    :class:`~gift.core.interfaces.LMBackend` wins (``gift-llm`` implements it). Called by :func:`gift.resolve_lm`."""


@hookspec
def gift_register_executors(register: Register) -> None:
    """Register :class:`gift.core.executor.Executor` factories (``local``, ``ray``, ...)."""


@hookspec
def gift_register_suites(register: Register) -> None:
    """Register benchmark suites: ``register(name, path_to_yaml)``."""


@hookspec
def gift_register_commands(register: RegisterCommand) -> None:
    """Register ``gift`` CLI subcommands."""


@hookspec
def gift_register_doctor_checks(register: Register) -> None:
    """Register checks of what the plugin needs, run by ``gift doctor``: ``register(name, check)`` where
    ``check(quick=False)`` returns a :class:`gift.doctor.Check` or a list of them."""
