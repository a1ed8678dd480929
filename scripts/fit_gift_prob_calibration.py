"""Fit gift-prob's pooled term calibration on development suites and write the file gift-kernels ships.

Input: ``gift evaluate-alignment --out`` results of a ``gift-prob`` kernel on DEVELOPMENT suites (never on a
suite the calibration is reported on). The kernel's per-object terms (``details.terms``: the LM log-odds
of the chosen category and the MiniLM term) of every test object, with the suite's labels, are pooled;
:meth:`gift_kernels.calibration.TermCalibration.fit` fits one logistic model. The file records the suites,
intents, intent sources, object count, the kernel spec and the git commit.

    python scripts/fit_gift_prob_calibration.py out/r16/gift-dev-*.json out/r16/lm_dev_suite-*.json \\
        --prior-sd 1.0 --out plugins/kernels/gift_kernels/data/gift_prob_calibration.json
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
from collections.abc import Sequence
from pathlib import Path

import numpy as np
from gift_kernels.calibration import TermCalibration

from gift.study.sweeps import recorded_suite


def collect(paths: Sequence[str], kernel_prefix: str = "gift-prob") -> tuple[np.ndarray, np.ndarray, dict]:
    X, y, seen = [], [], {"suites": {}, "kernels": set()}
    for path in paths:
        res = json.loads(Path(path).read_text(encoding="utf-8"))
        suite = recorded_suite(res, str(path))
        for kname, k in res["kernels"].items():
            if not kname.startswith(kernel_prefix):
                continue
            seen["kernels"].add(kname)
            for iid, rec in k["intents"].items():
                terms = (rec.get("details") or {}).get("terms") or {}
                if "lm" not in terms or "language" not in terms:
                    continue
                spec = suite.intent(iid)
                X += list(zip(terms["lm"]["test"], terms["language"]["test"]))
                y += [t.relevant for t in spec.test]
                seen["suites"].setdefault(suite.name, set()).add(f"{iid} ({res['intent_source']})")
    return np.asarray(X, float), np.asarray(y, bool), seen


def main(argv: Sequence[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("results", nargs="+", help="evaluate-alignment JSON results on development suites")
    p.add_argument("--prior-sd", type=float, default=1.0, help="per-intent update strength")
    p.add_argument("--out", default=None, help="write the calibration here (default: print it)")
    args = p.parse_args(argv)
    X, y, seen = collect(args.results)
    if not len(y):
        raise SystemExit("no gift-prob terms found in the results (run gift-prob with this version of gift)")
    commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], capture_output=True, text=True).stdout.strip()
    fitted_on = {"suites": {s: sorted(v) for s, v in seen["suites"].items()}, "objects": int(len(y)),
                 "relevant": int(y.sum()), "kernels": sorted(seen["kernels"]), "commit": commit,
                 "script": "scripts/fit_gift_prob_calibration.py"}
    cal = TermCalibration.fit(X, y, prior_sd=args.prior_sd, fitted_on=fitted_on)
    text = json.dumps(cal.to_dict(), indent=1)
    if args.out:
        Path(args.out).write_text(text + "\n", encoding="utf-8")
    print(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
