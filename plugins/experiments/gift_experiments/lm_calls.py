"""The LM calls of a run: recorded by :class:`gift_llm.replay.RecordingLM` into ``out/lm_calls.jsonl``
(the same file ``--lm replay:out/lm_calls.jsonl`` replays), read back for the HTML report.

:func:`recording` sets ``GIFT_LM_RECORD`` for the duration of a command (unless the user set it already,
then that file is used) and makes the study resolve its LM again, so every LM the run uses records its
calls, in worker processes too.
The file holds the calls of the last invocation: stages resumed from ``out/stages`` make none.
"""

from __future__ import annotations

import contextlib
import json
import logging
import os
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import attrs

from gift.study.components import reset_components

log = logging.getLogger(__name__)

LM_CALLS = "lm_calls.jsonl"
ENV = "GIFT_LM_RECORD"


@contextlib.contextmanager
def recording(out: Path, lm: str | None = None) -> Iterator[Path]:
    """Record the LM calls made inside the block into ``out/lm_calls.jsonl`` (emptied first); yields the
    file. With ``$GIFT_LM_RECORD`` already set, that file records them and is yielded instead. When the
    run's LM (``lm``, else ``$GIFT_LM``) replays ``out/lm_calls.jsonl`` itself, the file is left as it is
    (it holds the calls being replayed) and nothing more is recorded."""
    if os.environ.get(ENV, "").strip():
        yield Path(os.environ[ENV]).expanduser()
        return
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    path = (out / LM_CALLS).resolve()
    spec = (lm or os.environ.get("GIFT_LM", "")).strip()
    if spec.startswith("replay:") and Path(spec.partition(":")[2]).expanduser().resolve() == path:
        log.info("replaying %s: not recording over it", path)
        yield path
        return
    path.write_text("")
    os.environ[ENV] = str(path)
    reset_components()  # the study's LM is resolved again, now wrapped by the recorder
    try:
        yield path
    finally:
        if os.environ.get(ENV) == str(path):
            del os.environ[ENV]
        reset_components()  # and not recorded into this file any more


@attrs.frozen
class LMCall:
    """One recorded call. ``kind``: ``complete`` or ``choices``; ``messages``: ``[{"role", "content"}]``;
    ``answer``: the completion text, or the choice probabilities as ``"yes 0.93, no 0.07"``; tokens as
    the model counted them when it answered (a cache hit repeats them); ``cached``: answered from the
    cache (None: unknown, e.g. a recording made before this was recorded); ``seconds``: wall clock."""

    index: int
    kind: str
    identity: str
    messages: tuple[dict[str, str], ...]
    answer: str
    prompt_tokens: int | None = None
    completion_tokens: int | None = None
    cached: bool | None = None
    seconds: float | None = None
    parameters: dict[str, Any] = attrs.field(factory=dict)


def read_calls(path: Path) -> list[LMCall]:
    """The calls of a recording file, in order; unreadable lines are skipped with a warning."""
    calls: list[LMCall] = []
    with open(path, encoding="utf-8") as f:
        for lineno, line in enumerate(f, 1):
            if not line.strip():
                continue
            try:
                rec = json.loads(line)
                req, resp = rec["request"], rec["response"]
                kind = req.get("kind", "complete")
                if kind == "choices":
                    answer = ", ".join(f"{c} {float(p):.3f}" for c, p in sorted(resp.items(), key=lambda kv: -kv[1]))
                    tokens = (None, None)
                else:
                    answer = str(resp.get("text", ""))
                    u = resp.get("usage") or {}
                    tokens = (u.get("prompt_tokens"), u.get("completion_tokens"))
                params = {k: v for k, v in req.items() if k not in ("kind", "messages") and v is not None}
                calls.append(LMCall(len(calls) + 1, kind, str(rec.get("identity", "")),
                                    tuple({"role": str(m.get("role", "")), "content": str(m.get("content", ""))}
                                          for m in req.get("messages", [])), answer, tokens[0], tokens[1],
                                    rec.get("cached"), rec.get("seconds"), params))
            except (ValueError, KeyError, TypeError, AttributeError) as e:
                log.warning("%s line %d is not an LM call record: %s", path, lineno, e)
    return calls
