"""How often Call 3 needed repairs or fell back, read from an LM recording (``GIFT_LM_RECORD=run.jsonl``).

Each Call-3 sample is one chain of requests: the first answer, then one request per repair (the repair
prompt of ``gift_llm.structured``). Every answer is validated again with ``parse_mapping`` against the
objects its prompt lists; a chain whose last answer is invalid is a fallback (its unmapped objects
defaulted to distractor). Prints one JSON object with the totals, grouped by kernel (with / without the
intent) and by whether a JSON schema was sent.

Usage: ``.venv/bin/python scripts/call3_answer_stats.py run.jsonl [more.jsonl ...]``
"""

from __future__ import annotations

import json
import sys
from collections import Counter, defaultdict
from pathlib import Path

from gift.core.errors import LMAnswerError, ValidationError
from gift_kernels import prompts
from gift_kernels.lm_kernels import _valid_part, parse_mapping
from gift_llm.parsing import extract_dict
from gift_llm.structured import REPAIR_PROMPT

REPAIR_HEAD = REPAIR_PROMPT.split("{problem}")[0]


def _listed(prompt: str, key: str) -> list[str]:
    return json.loads(next(ln for ln in prompt.splitlines() if ln.startswith(key)).split(":", 1)[1])


def chains(paths: list[Path]) -> list[list[dict]]:
    """Call-3 request chains (a first request and its repairs), in recorded order."""
    out: list[list[dict]] = []
    open_chain: dict[str, list[dict]] = {}  # the latest chain per first request
    for path in paths:
        for line in path.read_text(encoding="utf-8").splitlines():
            rec = json.loads(line)
            req = rec["request"]
            if req.get("kind") != "complete" or req["messages"][0]["content"] != prompts.MAP_SYSTEM:
                continue
            first = json.dumps([req["messages"][:2], req["seed"], req["temperature"], req["json_schema"]])
            if req["messages"][-1]["content"].startswith(REPAIR_HEAD) and first in open_chain:
                open_chain[first].append(rec)
            else:
                open_chain[first] = [rec]
                out.append(open_chain[first])
    return out


def stats(paths: list[Path]) -> dict:
    groups: dict[str, Counter] = defaultdict(Counter)
    for recs in chains(paths):
        req = recs[0]["request"]
        prompt = req["messages"][1]["content"]
        test, train = _listed(prompt, "New objects"), _listed(prompt, "Training objects")
        kernel = "lm-no-intent" if prompt.startswith("No goal is given") else "gift"
        g = groups[f"{kernel}, {'schema' if req['json_schema'] else 'free text'}"]
        g["samples"] += 1
        g["answers"] += len(recs)
        g["repairs"] += len(recs) - 1
        g["objects"] += len(test)
        last_ok = False
        for i, rec in enumerate(recs):
            try:
                parse_mapping(extract_dict(rec["response"]["text"]), test, train)
                ok = True
            except (LMAnswerError, ValidationError):
                ok = False
            g["invalid_answers"] += not ok
            last_ok = ok
        if not last_ok:
            g["fallbacks"] += 1
            try:
                valid, _ = _valid_part(extract_dict(recs[-1]["response"]["text"]), test, train)
            except LMAnswerError:
                valid = {}
            g["objects_defaulted"] += len(test) - len(valid)
        g["completion_tokens"] += sum(r["response"]["usage"]["completion_tokens"] for r in recs)
        g["model_seconds"] += round(sum(r["response"]["usage"]["latency_s"] for r in recs), 1)
    return {k: dict(v) for k, v in sorted(groups.items())}


if __name__ == "__main__":
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    print(json.dumps(stats([Path(p) for p in sys.argv[1:]]), indent=1))
