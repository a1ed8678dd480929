"""Plugin discovery (entry-point group ``gift``), the component registry, and lookup by name.

Environment variables:

- ``GIFT_PLUGINS``: comma-separated allow-list of entry-point names; only these are loaded
  (built-in plugins always load). Unset or empty: load every installed plugin.
- ``GIFT_DISABLE_PLUGINS``: comma-separated entry-point names never to load.

A plugin that fails to import (or whose hook raises) is skipped with a warning naming it; everything
else keeps working.
"""

from __future__ import annotations

import importlib
import importlib.metadata
import inspect
import os
import threading
import warnings
from collections.abc import Callable, Iterable, Mapping
from typing import Any

import attrs
import pluggy

from gift.core.errors import ComponentOptionError, PluginError, UnknownComponentError
from gift.plugins import hookspecs

ENTRY_POINT_GROUP = "gift"

#: kind -> hook that registers it.
KINDS: dict[str, str] = {
    "robot": "gift_register_robots",
    "simulator": "gift_register_simulators",
    "motion": "gift_register_motions",
    "task": "gift_register_tasks",
    "kernel": "gift_register_kernels",
    "intent_estimator": "gift_register_intent_estimators",
    "alignment_operator": "gift_register_alignment_operators",
    "query_policy": "gift_register_query_policies",
    "reward_model": "gift_register_reward_models",
    "lm_backend": "gift_register_lm_backends",
    "executor": "gift_register_executors",
    "suite": "gift_register_suites",
    "command": "gift_register_commands",
    "doctor_check": "gift_register_doctor_checks",
}

BUILTIN_PLUGINS = ("gift.tasks", "gift.suites", "gift.executors", "gift.alignment_operators", "gift.query_policies")
#: Called once per registered robot (``robot=spec``); what it registers is of kind ``simulator``.
ROBOT_SIMULATOR_HOOK = "gift_register_robot_simulators"


class PluginWarning(UserWarning):
    """A plugin could not be loaded or registered; it was skipped."""


@attrs.frozen
class Component:
    """One registered component. ``factory(**options)`` builds it."""

    kind: str
    name: str
    factory: Any
    plugin: str
    distribution: str
    description: str = ""
    extra: dict = attrs.field(factory=dict)

    def create(self, **options: Any) -> Any:
        """``factory(**options)``; options the factory does not take are a :class:`ComponentOptionError`
        listing the valid ones (checked against its signature before it is called). A robot is registered
        as data (a :class:`~gift.core.robots.RobotSpec`) and returned as it is."""
        if self.kind == "robot":
            if options:
                raise PluginError(f"robot {self.name!r} is a RobotSpec and takes no options, got {sorted(options)}")
            return self.factory
        self.check_options(options)
        return self.factory(**options)

    def options(self) -> list[str] | None:
        """Names of the options the factory takes (None when it takes any keyword or has no signature)."""
        params = _parameters(self.factory)
        if params is None or any(p.kind is inspect.Parameter.VAR_KEYWORD for p in params):
            return None
        return [p.name for p in params
                if p.kind in (inspect.Parameter.POSITIONAL_OR_KEYWORD, inspect.Parameter.KEYWORD_ONLY)]

    def check_options(self, options: Mapping[str, Any]) -> None:
        """Raise :class:`ComponentOptionError` if ``options`` do not fit the factory's signature."""
        params = _parameters(self.factory)
        if params is None:
            return
        valid = self.options()
        unknown = sorted(set(options) - set(valid)) if valid is not None else []
        what = f"{self.kind} {self.name!r} (plugin {self.plugin!r})"
        listed = ", ".join(valid) if valid else "none"
        if unknown:
            raise ComponentOptionError(f"{what} has no option{'s' if len(unknown) > 1 else ''} "
                                       f"{', '.join(map(repr, unknown))}; valid options: {listed}")
        try:
            inspect.Signature(params).bind(**options)
        except TypeError as e:  # a required option is missing
            raise ComponentOptionError(f"{what}: {e}; valid options: {listed}") from None

    def as_dict(self) -> dict[str, str]:
        return {"kind": self.kind, "name": self.name, "plugin": self.plugin, "distribution": self.distribution,
                "description": self.description}


def _parameters(factory: Any) -> list[inspect.Parameter] | None:
    """The parameters ``factory(**options)`` takes (a class: its ``__init__`` without ``self``), or None."""
    try:
        return list(inspect.signature(factory).parameters.values())
    except (TypeError, ValueError):  # builtins and some C extensions have no signature
        return None


def _env_list(var: str) -> set[str] | None:
    raw = os.environ.get(var, "").strip()
    return {x.strip() for x in raw.split(",") if x.strip()} if raw else None


class GiftPluginManager:
    """Loads plugins, collects their registrations and answers lookups."""

    def __init__(self) -> None:
        self.pm = pluggy.PluginManager("gift")
        self.pm.add_hookspecs(hookspecs)
        self._registry: dict[str, dict[str, Component]] = {k: {} for k in KINDS}
        self._distribution: dict[str, str] = {}
        self.failed: dict[str, str] = {}
        #: plugin name -> its distribution, for the plugins in :attr:`failed`
        self.failed_distributions: dict[str, str] = {}
        self._loaded = False

    # -------------------------------------------------------------------- loading
    def register_plugin(self, plugin: Any, name: str, distribution: str = "gift") -> None:
        """Register a plugin object or module directly (as tests and embedding code do)."""
        self.pm.register(plugin, name=name)
        self._distribution[name] = distribution
        if self._loaded:
            before = set(self._registry["robot"])
            self._collect_from(name)
            new = [r for n, r in self._registry["robot"].items() if n not in before]
            old = [r for n, r in self._registry["robot"].items() if n in before]
            self._collect_robot_simulators(new, None)  # every plugin's simulators for the new robots
            self._collect_robot_simulators(old, name)  # the new plugin's simulators for the known robots

    def load(self, entry_points: Iterable[importlib.metadata.EntryPoint] | None = None) -> "GiftPluginManager":
        if self._loaded:
            return self
        for mod in BUILTIN_PLUGINS:
            self.register_plugin(importlib.import_module(mod), name=mod, distribution="gift")
        allow = _env_list("GIFT_PLUGINS")
        deny = _env_list("GIFT_DISABLE_PLUGINS") or set()
        eps = entry_points if entry_points is not None else importlib.metadata.entry_points(group=ENTRY_POINT_GROUP)
        for ep in sorted(eps, key=lambda e: e.name):
            if (allow is not None and ep.name not in allow) or ep.name in deny:
                continue
            if self.pm.has_plugin(ep.name):
                continue
            dist = ep.dist.name if getattr(ep, "dist", None) is not None else "?"
            try:
                plugin = ep.load()
            except Exception as e:  # noqa: BLE001 - any import failure of a third-party plugin
                self.failed[ep.name] = f"{type(e).__name__}: {e}"
                self.failed_distributions[ep.name] = dist
                warnings.warn(f"gift plugin {ep.name!r} (distribution {dist!r}, {ep.value}) failed to import and "
                              f"was skipped: {type(e).__name__}: {e}", PluginWarning, stacklevel=2)
                continue
            self.pm.register(plugin, name=ep.name)
            self._distribution[ep.name] = dist
        self._loaded = True
        for name, _ in self.pm.list_name_plugin():
            self._collect_from(name)
        self._collect_robot_simulators(self._registry["robot"].values(), None)
        return self

    def _collect_from(self, plugin_name: str) -> None:
        plugin = self.pm.get_plugin(plugin_name)
        for kind, hook_name in KINDS.items():
            hook = getattr(self.pm.hook, hook_name)
            for impl in hook.get_hookimpls():
                if impl.plugin is not plugin:
                    continue
                try:
                    impl.function(register=self._registrar(kind, plugin_name))
                except PluginError:
                    raise
                except Exception as e:  # noqa: BLE001
                    self.failed[plugin_name] = f"{hook_name}: {type(e).__name__}: {e}"
                    self.failed_distributions[plugin_name] = self._distribution.get(plugin_name, "?")
                    warnings.warn(f"gift plugin {plugin_name!r}: hook {hook_name} raised {type(e).__name__}: {e}; "
                                  f"its remaining registrations were skipped", PluginWarning, stacklevel=2)

    def _collect_robot_simulators(self, robots: Iterable[Any], only_plugin: str | None) -> None:
        """Call :data:`ROBOT_SIMULATOR_HOOK` for each robot (of every plugin, or of ``only_plugin``)."""
        robots = sorted((c.factory for c in robots), key=lambda r: r.name)
        for impl in getattr(self.pm.hook, ROBOT_SIMULATOR_HOOK).get_hookimpls():
            plugin_name = self.pm.get_name(impl.plugin)
            if only_plugin is not None and plugin_name != only_plugin:
                continue
            for robot in robots:
                try:
                    impl.function(register=self._registrar("simulator", plugin_name, robot=robot.name), robot=robot)
                except PluginError:
                    raise
                except Exception as e:  # noqa: BLE001
                    self.failed[plugin_name] = f"{ROBOT_SIMULATOR_HOOK}({robot.name}): {type(e).__name__}: {e}"
                    warnings.warn(f"gift plugin {plugin_name!r}: hook {ROBOT_SIMULATOR_HOOK} raised "
                                  f"{type(e).__name__}: {e} for robot {robot.name!r}; no simulator of it registered",
                                  PluginWarning, stacklevel=2)

    def _registrar(self, kind: str, plugin_name: str, robot: str | None = None) -> Callable[..., None]:
        dist = self._distribution.get(plugin_name, "?")

        def register(name: Any, factory: Any = None, *, description: str = "", help: str = "", **extra: Any) -> None:
            description = description or help
            if factory is None and not isinstance(name, str):  # register(MyKernel): the name is the class's
                factory, name = name, getattr(name, "name", None)
                if not isinstance(name, str):
                    raise PluginError(f"plugin {plugin_name!r} registered a {kind} {factory!r} without a name: "
                                      f"give it a class attribute 'name' or call register('name', factory)")
            if not isinstance(name, str) or not name.strip():
                raise PluginError(f"plugin {plugin_name!r} registered a {kind} with an invalid name {name!r}")
            if factory is None:
                raise PluginError(f"plugin {plugin_name!r} registered {kind} {name!r} without a factory")
            own = getattr(factory, "name", None) if isinstance(factory, type) else None
            if isinstance(own, str) and own != name:
                raise PluginError(f"plugin {plugin_name!r} registered the {kind} class {factory.__name__} as {name!r}, "
                                  f"but its name attribute is {own!r}: a component's name has one source; "
                                  f"use register({factory.__name__}) or make them agree")
            if kind == "robot":
                description = description or _check_robot(plugin_name, name, factory)
            if robot is not None:
                extra = {**extra, "robot": robot}
            existing = self._registry[kind].get(name)
            if existing is not None:
                raise PluginError(f"two plugins register the {kind} {name!r}: {existing.plugin!r} (distribution "
                                  f"{existing.distribution!r}) and {plugin_name!r} (distribution {dist!r}); "
                                  f"uninstall one or disable it with GIFT_DISABLE_PLUGINS")
            if not description and kind not in ("suite", "robot"):
                doc = getattr(factory, "__doc__", None) or ""
                description = doc.strip().splitlines()[0] if doc.strip() else ""
            self._registry[kind][name] = Component(kind, name, factory, plugin_name, dist, description, extra)

        return register

    # -------------------------------------------------------------------- lookup
    def components(self, kind: str | None = None) -> list[Component]:
        kinds = [kind] if kind else list(KINDS)
        return [c for k in kinds for c in sorted(self._registry[self._kind(k)].values(), key=lambda c: c.name)]

    def names(self, kind: str) -> list[str]:
        return sorted(self._registry[self._kind(kind)])

    def get(self, kind: str, name: str) -> Component:
        kind = self._kind(kind)
        try:
            return self._registry[kind][name]
        except KeyError:
            known = ", ".join(sorted(self._registry[kind])) or "none"
            hint = f" (plugins that failed to load: {sorted(self.failed)})" if self.failed else ""
            raise UnknownComponentError(f"no {kind} named {name!r}; registered: {known}{hint}") from None

    def create(self, kind: str, name: str, **options: Any) -> Any:
        """Build ``name`` of ``kind``; the built component must carry that name (when it has a ``name``)."""
        comp = self.get(kind, name)
        obj = comp.create(**options)
        own = getattr(obj, "name", None) if kind not in ("suite", "command") else None
        if isinstance(own, str) and own != name:
            raise PluginError(f"the {kind} registered as {name!r} by plugin {comp.plugin!r} built a "
                              f"{type(obj).__name__} named {own!r}: a component's name has one source")
        return obj

    def simulators_for_robot(self, robot: str) -> list[str]:
        """Names of the simulators registered for ``robot`` (through ``gift_register_robot_simulators``)."""
        self.get("robot", robot)  # unknown robots: the usual error listing the registered ones
        return sorted(c.name for c in self._registry["simulator"].values() if c.extra.get("robot") == robot)

    def suites(self) -> dict[str, str]:
        return {c.name: str(c.factory) for c in self._registry["suite"].values()}

    @staticmethod
    def _kind(kind: str) -> str:
        if kind not in KINDS:
            raise PluginError(f"unknown component kind {kind!r}; kinds: {sorted(KINDS)}")
        return kind


def _check_robot(plugin_name: str, name: str, spec: Any) -> str:
    """A registered robot must be a RobotSpec named like its registration; returns its description."""
    from gift.core.robots import RobotSpec

    if not isinstance(spec, RobotSpec):
        raise PluginError(f"plugin {plugin_name!r} registered robot {name!r} as a {type(spec).__name__}; register a "
                          f"gift.core.robots.RobotSpec")
    if spec.name != name:
        raise PluginError(f"plugin {plugin_name!r} registered robot {name!r} with a RobotSpec named {spec.name!r}; "
                          f"the two names must agree")
    return spec.description


_manager: GiftPluginManager | None = None
_lock = threading.Lock()


def get_manager() -> GiftPluginManager:
    """The process-wide plugin manager, loaded on first use."""
    global _manager
    with _lock:
        if _manager is None:
            _manager = GiftPluginManager().load()
        return _manager


def reset_manager() -> None:
    """Forget the loaded plugins (the next lookup discovers them again)."""
    global _manager
    with _lock:
        _manager = None
