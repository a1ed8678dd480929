"""gift: Generalizing Intent for Flexible Test-time rewards.

Lookup of registered components::

    import gift
    kernel = gift.get_kernel("language")
    lm = gift.resolve_lm()            # the embedded LM (or $GIFT_LM), cached
    gift.list_components()            # {"kernel": [...], "simulator": [...], ...}
    gift.get_robot("franka")          # a RobotSpec; gift.robot_simulator("franka") -> "drake-franka"
"""

from __future__ import annotations

from typing import Any

from gift.core.data import (
    DISTRACTOR,
    Alignment,
    Appearance,
    Completion,
    DemonstrationPair,
    FeatureBatch,
    FeatureSpec,
    FeatureTrace,
    Intent,
    Message,
    Motivation,
    ObjectSpec,
    Scene,
    SemanticAxis,
    Trajectory,
    TrajectoryBatch,
    Usage,
)
from gift.core.errors import GiftError, LMAnswerError, LMError, PluginError, SuiteError, UnknownComponentError
from gift.core.pipeline import GiftPipeline
from gift.core.robots import RobotSpec
from gift.core.suite import Suite, load_suite
from gift.plugins.hookspecs import hookimpl
from gift.plugins.manager import get_manager

__version__ = "0.1.0"


def get_component(kind: str, name: str, **options: Any) -> Any:
    """Build the registered component ``name`` of ``kind`` with ``options``."""
    return get_manager().create(kind, name, **options)


def get_simulator(name: str, **options: Any):
    return get_component("simulator", name, **options)


def get_robot(name: str) -> RobotSpec:
    """The registered robot ``name`` (a :class:`~gift.core.robots.RobotSpec`)."""
    return get_manager().create("robot", name)


def robot_simulator(robot: str) -> str:
    """The name of the simulator registered for ``robot`` (e.g. ``"drake-franka"``; the first by name when
    several simulator plugins build one). Raises :class:`UnknownComponentError` when there is none."""
    names = get_manager().simulators_for_robot(robot)
    if not names:
        raise UnknownComponentError(f"robot {robot!r} is registered but no simulator is built for it; install a "
                                    f"simulator plugin such as gift-sim-drake")
    return names[0]


def get_task(name: str, **options: Any):
    return get_component("task", name, **options)


def get_kernel(name: str, **options: Any):
    return get_component("kernel", name, **options)


def get_intent_estimator(name: str, **options: Any):
    return get_component("intent_estimator", name, **options)


def get_alignment_operator(name: str, **options: Any):
    return get_component("alignment_operator", name, **options)


def get_query_policy(name: str, **options: Any):
    return get_component("query_policy", name, **options)


def get_reward_model(name: str, **options: Any):
    return get_component("reward_model", name, **options)


def resolve_lm(spec: Any = None, **options: Any):
    """The one way to get an LM: ``spec`` is None (``$GIFT_LM`` or the embedded default), a registered
    backend name, ``"backend:model"`` (``"litellm:openai/gpt-4o"``), or an LM backend instance (returned
    as is). Names are resolved by the plugin implementing ``gift_resolve_lm`` (``gift-llm``: cached,
    optionally recorded; ``cache=False`` for a bare backend)."""
    from gift.core.errors import LMError
    from gift.core.interfaces import LMBackend

    if isinstance(spec, LMBackend) or (spec is not None and not isinstance(spec, str) and hasattr(spec, "complete")):
        if options:
            raise LMError(f"resolve_lm: options {sorted(options)} cannot apply to an LM instance")
        return spec
    if spec is not None and not isinstance(spec, str):
        raise LMError(f"resolve_lm: expected a backend name, a 'backend:model' string or an LM backend, got "
                      f"{type(spec).__name__}")
    lm = get_manager().pm.hook.gift_resolve_lm(spec=spec, options=dict(options))
    if lm is None:
        raise LMError("no plugin resolves LM names: install gift-llm (pip install -e plugins/llm)")
    return lm


def list_components(kind: str | None = None) -> dict[str, list[dict[str, str]]]:
    """Every registered component by kind: ``{kind: [{name, plugin, distribution, description}]}``."""
    out: dict[str, list[dict[str, str]]] = {}
    for c in get_manager().components(kind):
        out.setdefault(c.kind, []).append(c.as_dict())
    return out


__all__ = [
    "DISTRACTOR", "Alignment", "Appearance", "Completion", "DemonstrationPair", "FeatureBatch", "FeatureSpec",
    "FeatureTrace", "Intent", "Message", "Motivation", "ObjectSpec", "Scene", "SemanticAxis", "Trajectory",
    "TrajectoryBatch", "Usage", "RobotSpec", "GiftError", "LMAnswerError", "LMError", "PluginError", "SuiteError",
    "UnknownComponentError", "GiftPipeline", "Suite", "load_suite", "hookimpl", "get_manager", "get_component",
    "get_simulator", "get_robot", "robot_simulator", "get_task", "get_kernel", "get_intent_estimator",
    "get_alignment_operator", "get_query_policy", "get_reward_model", "resolve_lm", "list_components",
]
