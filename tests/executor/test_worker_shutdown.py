"""Pool workers die with the process that started them, even when it is killed with SIGKILL.

A real sweep (``gift evaluate-alignment`` with the language and vision kernels on ``--executor local
--workers 2``) runs in a subprocess with an empty cache, so its workers are busy loading models, rendering
objects and embedding them. The CLI process is killed with ``kill -9`` once both workers run; then every
process it had started (the two workers and multiprocessing's resource tracker) must be gone within a few
seconds: none may keep computing, re-parented to PID 1.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

pytestmark = [pytest.mark.slow]

SUITE = Path(__file__).parents[1] / "kernels" / "data" / "mini_suite.yaml"


def _stat(pid: int) -> tuple[int, str, int] | None:
    """``(ppid, state, start time)`` from ``/proc/<pid>/stat``, or None when the process does not exist."""
    try:
        text = Path(f"/proc/{pid}/stat").read_text()
    except (FileNotFoundError, ProcessLookupError):
        return None
    fields = text[text.rindex(")") + 2:].split()  # after "pid (comm) "
    return int(fields[1]), fields[0], int(fields[19])


def _descendants(root: int) -> dict[int, int]:
    """``{pid: start time}`` of every live process below ``root``."""
    parent: dict[int, int] = {}
    started: dict[int, int] = {}
    for entry in os.listdir("/proc"):
        if entry.isdigit() and (st := _stat(int(entry))) is not None:
            parent[int(entry)], started[int(entry)] = st[0], st[2]
    out, frontier = {}, [root]
    while frontier:
        p = frontier.pop()
        for child, pp in parent.items():
            if pp == p and child not in out:
                out[child] = started[child]
                frontier.append(child)
    return out


def _alive(pid: int, start: int) -> bool:
    """The same process (not a reused pid) still exists and is not a zombie."""
    st = _stat(pid)
    return st is not None and st[2] == start and st[1] != "Z"


def _cmdline(pid: int) -> str:
    try:
        return Path(f"/proc/{pid}/cmdline").read_bytes().replace(b"\0", b" ").decode(errors="replace")
    except OSError:
        return "?"


@pytest.mark.skipif(not Path("/proc/self/stat").exists(), reason="reads the process table from /proc")
def test_sigkill_of_a_sweep_leaves_no_worker_running(tmp_path):
    env = {**os.environ, "GIFT_CACHE_DIR": str(tmp_path / "cache"), "PYTHONUNBUFFERED": "1"}
    log = open(tmp_path / "stderr.txt", "wb")
    cli = subprocess.Popen([sys.executable, "-m", "gift.cli", "evaluate-alignment", "--suite", str(SUITE),
                            "--kernels", "language,vision", "--intent-source", "ground-truth",
                            "--executor", "local", "--workers", "2", "--quiet"],
                           env=env, stdout=subprocess.DEVNULL, stderr=log)
    started: dict[int, int] = {}
    try:
        deadline = time.monotonic() + 120
        workers: dict[int, int] = {}
        while len(workers) < 2:  # wait until both pool workers are up and have been working for a moment
            assert cli.poll() is None, (f"the sweep ended ({cli.returncode}) before it could be killed:\n"
                                        f"{(tmp_path / 'stderr.txt').read_text()[-3000:]}")
            assert time.monotonic() < deadline, "the sweep never started its 2 workers"
            workers = {p: s for p, s in _descendants(cli.pid).items() if "spawn_main" in _cmdline(p)
                       and "resource_tracker" not in _cmdline(p)}
            time.sleep(0.2)
        time.sleep(3.0)
        assert cli.poll() is None, "the sweep finished before it could be killed; make it longer"
        started = _descendants(cli.pid)
        assert set(workers) <= set(started)
        os.kill(cli.pid, signal.SIGKILL)
        cli.wait(timeout=10)
        deadline = time.monotonic() + 5.0
        while (alive := {p for p, s in started.items() if _alive(p, s)}) and time.monotonic() < deadline:
            time.sleep(0.1)
        assert not alive, (f"{len(alive)} of the {len(started)} processes the killed sweep had started still run "
                           f"5 s later: " + "; ".join(f"{p}: {_cmdline(p)[:120]}" for p in sorted(alive)))
    finally:
        log.close()
        if cli.poll() is None:
            cli.kill()
            cli.wait()
        for p, s in started.items():  # never leave a stray process behind, whatever the outcome
            if _alive(p, s):
                os.kill(p, signal.SIGKILL)


def test_die_with_parent_ends_an_orphaned_grandchild(tmp_path):
    """The mechanism on its own: a child that called :func:`die_with_parent` ends when its parent is SIGKILLed,
    also while it is busy in pure Python, and exits with ORPHAN_EXIT_STATUS."""
    script = tmp_path / "family.py"
    script.write_text(
        "import subprocess, sys, time\n"
        "child = subprocess.Popen([sys.executable, '-c', 'from gift.core.executor import die_with_parent; "
        "die_with_parent(); print(\"ready\", flush=True)\\nwhile True: sum(range(10000))'], "
        "stdout=subprocess.PIPE)\n"
        "assert child.stdout.readline().strip() == b'ready'\n"
        "print(child.pid, flush=True)\n"
        "time.sleep(600)\n")
    parent = subprocess.Popen([sys.executable, str(script)], stdout=subprocess.PIPE)
    try:
        pid = int(parent.stdout.readline())
        st = _stat(pid)
        assert st is not None and st[0] == parent.pid
        os.kill(parent.pid, signal.SIGKILL)
        parent.wait(timeout=10)
        deadline = time.monotonic() + 5.0
        while _alive(pid, st[2]) and time.monotonic() < deadline:
            time.sleep(0.05)
        assert not _alive(pid, st[2]), "the orphaned child still runs 5 s after its parent was killed"
    finally:
        if parent.poll() is None:
            parent.kill()
            parent.wait()
