#!/usr/bin/env bash
# Install the developer set when .venv is missing, broken or out of date, then run the test suite
# (benchmarks included). Arguments go to pytest: bash scripts/test.sh -m "not slow" -x
#
# "Out of date" is decided by a hash of scripts/setup.sh, constraints.txt, the CMake file and every
# pyproject.toml, stored in .venv/.setup/stamp-dev by the last successful `scripts/setup.sh --dev`.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh --dev --if-changed
exec .venv/bin/python -m pytest "$@"
