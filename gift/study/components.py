"""Building registered components for a study: one builder, one cache per process.

A component is named by a *spec*: ``"name"`` or ``"name:key=value:key=value"`` (values ``true``/``false``,
ints, floats, else strings). :func:`build` is the one place that turns a spec into an object: it
passes the study's LM (``lm=``) and study-wide defaults (e.g. ``samples=``) only to factories whose
signature takes them, so a kernel without an LM never sees ``lm``. :class:`Components` keeps what it
built, and :func:`components_for` keeps one :class:`Components` per configuration and process, so a
worker that runs many items of a sweep loads each model once.
"""

from __future__ import annotations

import inspect
import threading
from collections.abc import Mapping
from typing import Any

from gift.core.errors import GiftError


def parse_spec(spec: str) -> tuple[str, dict[str, Any]]:
    """``"name"`` or ``"name:key=value:key=value"`` -> ``(name, options)``; values true/false/int/float/str."""
    name, *opts = spec.strip().split(":")
    options: dict[str, Any] = {}
    for o in opts:
        if "=" not in o:
            raise GiftError(f"option {o!r} in {spec!r} must look like key=value")
        k, v = o.split("=", 1)
        options[k.strip()] = _value(v.strip())
    if not name:
        raise GiftError(f"empty component name in {spec!r}")
    return name, options


def _value(v: str) -> Any:
    if v.lower() in ("true", "false"):
        return v.lower() == "true"
    for cast in (int, float):
        try:
            return cast(v)
        except ValueError:
            pass
    return v


def accepts(factory: Any, option: str) -> bool:
    """Whether ``factory``'s signature names the parameter ``option`` (a bare ``**kwargs`` does not count:
    a factory that wants the study's LM or a study-wide default says so by name)."""
    try:
        params = inspect.signature(factory).parameters
    except (TypeError, ValueError):
        return False
    p = params.get(option)
    return p is not None and p.kind in (inspect.Parameter.POSITIONAL_OR_KEYWORD, inspect.Parameter.KEYWORD_ONLY)


def build(kind: str, spec: str, *, lm: Any = None, defaults: Mapping[str, Any] | None = None) -> Any:
    """Build the registered ``kind`` named by ``spec``.

    ``lm`` (an LM spec or instance) and each of ``defaults`` go to the factory only when its signature
    takes them; options written in the spec win over ``defaults``.
    """
    from gift.plugins.manager import get_manager

    name, options = parse_spec(spec)
    manager = get_manager()
    factory = manager.get(kind, name).factory
    extra = {k: v for k, v in (defaults or {}).items() if k not in options and accepts(factory, k)}
    if lm is not None and "lm" not in options and accepts(factory, "lm"):
        extra["lm"] = lm
    return manager.create(kind, name, **extra, **options)


def check_spec(kind: str, spec: str) -> str | None:
    """Why ``spec`` cannot name a ``kind`` (bad syntax, unknown name), or None; nothing is built."""
    from gift.plugins.manager import get_manager

    try:
        name, _ = parse_spec(spec)
        get_manager().get(kind, name)
    except Exception as e:  # noqa: BLE001 - reported like a failing component
        return f"{type(e).__name__}: {e}"
    return None


def _public_counters(stats: Any) -> dict[str, Any] | None:
    """The public fields of an LM's usage counters (``stats``), or None."""
    if stats is None:
        return None
    import attrs

    fields = attrs.asdict(stats, recurse=False) if attrs.has(type(stats)) else vars(stats)
    # a snapshot: mappings of counts (answers per build) are copied, not shared with the live counters
    return {k: (dict(v) if isinstance(v, dict) else v) for k, v in fields.items() if not k.startswith("_")}


class Components:
    """The registered components one study uses, each built on first use and kept.

    ``lm``: the LM spec (None: ``$GIFT_LM`` or the embedded default) for every component that takes one;
    ``defaults``: options given to every factory that takes them (e.g. ``{"samples": 10}``).
    """

    def __init__(self, lm: Any = None, defaults: Mapping[str, Any] | None = None) -> None:
        self.lm_spec = lm
        self.defaults = dict(defaults or {})
        self._built: dict[tuple[str, str], Any] = {}
        self._lm: Any = None
        self.lm_usage_baseline: dict[str, Any] | None = None
        self._lock = threading.RLock()

    @property
    def lm(self) -> Any:
        """The resolved LM (built on first use, shared by every component of this study)."""
        with self._lock:
            if self._lm is None:
                import gift

                lm = gift.resolve_lm(self.lm_spec)
                # a resolved LM may be a process-wide instance that counted calls before this study:
                # usage is reported from here on (see gift.study.chain._lm_usage)
                self.lm_usage_baseline = _public_counters(getattr(lm, "stats", None))
                self._lm = lm
            return self._lm

    @property
    def lm_built(self) -> bool:
        return self._lm is not None

    def get(self, kind: str, spec: str) -> Any:
        with self._lock:
            key = (kind, spec)
            if key not in self._built:
                from gift.plugins.manager import get_manager

                factory = get_manager().get(kind, parse_spec(spec)[0]).factory
                lm = self.lm if accepts(factory, "lm") and "lm" not in parse_spec(spec)[1] else None
                self._built[key] = build(kind, spec, lm=lm, defaults=self.defaults)
            return self._built[key]

    def simulator(self, name: str) -> Any:
        return self.get("simulator", name)

    def task(self, name: str) -> Any:
        return self.get("task", name)

    def kernel(self, spec: str) -> Any:
        return self.get("kernel", spec)

    def estimator(self, spec: str) -> Any:
        return self.get("intent_estimator", spec)

    def reward(self, spec: str) -> Any:
        """A fresh, unfitted reward model (never cached: each intent fits its own)."""
        return build("reward_model", spec, lm=None, defaults=self.defaults)


_WORKER: dict[tuple, Components] = {}
_WORKER_LOCK = threading.Lock()


def components_for(lm: Any = None, defaults: Mapping[str, Any] | None = None) -> Components:
    """The :class:`Components` of this process for ``(lm, defaults)``: one per worker, reused by every item."""
    key = (lm if lm is None or isinstance(lm, str) else id(lm), tuple(sorted((defaults or {}).items())))
    with _WORKER_LOCK:
        if key not in _WORKER:
            _WORKER[key] = Components(lm, defaults)
        return _WORKER[key]


def reset_components() -> None:
    """Forget this process's :class:`Components` (the next study builds its components, and resolves its LM,
    again): for a change of the environment that decides how the LM is wrapped, e.g. ``GIFT_LM_RECORD``."""
    with _WORKER_LOCK:
        _WORKER.clear()
