"""Print the headline table of several `gift reproduce` runs: `python scripts/reproduce_summary.py LABEL=DIR ...`.

Each DIR holds a run's results.json; LABEL names its columns (e.g. `jaco=docs/results/reproduce/jaco`).
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

from gift_experiments.report import headline_table


def main(argv: list[str]) -> int:
    if not argv or any("=" not in a for a in argv):
        print(__doc__.strip(), file=sys.stderr)
        return 2
    runs = {}
    for arg in argv:
        label, path = arg.split("=", 1)
        runs[label] = json.loads((Path(path) / "results.json").read_text())
    threshold = next(iter(runs.values()))["config"]["thresholds"][0]
    print(headline_table(runs, threshold))
    return 0


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
