"""LM faults a user meets: a server that never answers, credentials inside ``--api-base``, a damaged cache file.

The servers are real TCP/HTTP servers started by the tests on 127.0.0.1 (one that accepts and never answers,
one that drops every connection, and a small OpenAI-compatible chat server that records what it receives);
litellm talks to them over real sockets, in-process or through the ``gift`` command in a subprocess.
"""

from __future__ import annotations

import base64
import json
import logging
import os
import socket
import sqlite3
import subprocess
import sys
import threading
import time
from collections.abc import Iterator
from contextlib import contextmanager
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from pathlib import Path

import pytest

from gift.core.errors import LMError

GIFT = [str(Path(sys.executable).with_name("gift"))]
PASSWORD = "pw-SECRET-7f3a9c"
QUERY_KEY = "qk-SECRET-0b8e21"


def _gift(*args: str, env: dict | None = None, timeout: float = 180) -> subprocess.CompletedProcess:
    return subprocess.run(GIFT + list(args), capture_output=True, text=True, timeout=timeout,
                          env={**os.environ, **(env or {})})


# ----------------------------------------------------------------------------- servers


@contextmanager
def silent_server() -> Iterator[str]:
    """Accepts connections and reads requests but never answers; yields the ``/v1`` URL."""
    srv = socket.socket()
    srv.bind(("127.0.0.1", 0))
    srv.listen(16)
    held: list[socket.socket] = []
    stop = threading.Event()

    def accept() -> None:
        srv.settimeout(0.2)
        while not stop.is_set():
            try:
                conn, _ = srv.accept()
                held.append(conn)  # keep it open: the client waits for an answer that never comes
            except OSError:
                continue

    t = threading.Thread(target=accept, daemon=True)
    t.start()
    try:
        yield f"http://127.0.0.1:{srv.getsockname()[1]}/v1"
    finally:
        stop.set()
        t.join(5)
        for c in held:
            c.close()
        srv.close()


@contextmanager
def dropping_server() -> Iterator[str]:
    """Accepts each connection and closes it at once (the client sees a connection error)."""
    srv = socket.socket()
    srv.bind(("127.0.0.1", 0))
    srv.listen(16)
    stop = threading.Event()

    def accept() -> None:
        srv.settimeout(0.2)
        while not stop.is_set():
            try:
                conn, _ = srv.accept()
                conn.close()
            except OSError:
                continue

    t = threading.Thread(target=accept, daemon=True)
    t.start()
    try:
        yield f"http://127.0.0.1:{srv.getsockname()[1]}/v1"
    finally:
        stop.set()
        t.join(5)
        srv.close()


class ChatServer(ThreadingHTTPServer):
    """An OpenAI-compatible ``/chat/completions`` that answers "4"; a path containing ``/fail/`` answers 401
    with an error message that echoes the request line and the credentials it got (as careless servers do)."""

    daemon_threads = True

    def __init__(self) -> None:
        super().__init__(("127.0.0.1", 0), _ChatHandler)
        self.requests: list[dict] = []


class _ChatHandler(BaseHTTPRequestHandler):
    def log_message(self, *args) -> None:  # quiet
        pass

    def do_POST(self) -> None:  # noqa: N802 - http.server's naming
        body = self.rfile.read(int(self.headers.get("Content-Length", 0)))
        self.server.requests.append({"path": self.path, "headers": dict(self.headers), "body": body.decode()})
        if "/fail/" in self.path:
            msg = f"bad credentials for {self.path} ({self.headers.get('Authorization')})"
            self._send(401, {"error": {"message": msg, "type": "invalid_request_error", "code": "invalid_api_key"}})
            return
        self._send(200, {"id": "chatcmpl-1", "object": "chat.completion", "created": int(time.time()),
                         "model": "test-model",
                         "choices": [{"index": 0, "finish_reason": "stop",
                                      "message": {"role": "assistant", "content": "4"}}],
                         "usage": {"prompt_tokens": 12, "completion_tokens": 1, "total_tokens": 13}})

    def _send(self, status: int, doc: dict) -> None:
        data = json.dumps(doc).encode()
        self.send_response(status)
        self.send_header("Content-Type", "application/json")
        self.send_header("Content-Length", str(len(data)))
        self.end_headers()
        self.wfile.write(data)


@pytest.fixture
def chat_server() -> Iterator[ChatServer]:
    srv = ChatServer()
    t = threading.Thread(target=srv.serve_forever, daemon=True)
    t.start()
    try:
        yield srv
    finally:
        srv.shutdown()
        srv.server_close()


# ----------------------------------------------------------------------------- timeouts


@pytest.mark.slow
def test_a_server_that_never_answers_fails_within_the_timeout():
    from gift_llm.backends.litellm_backend import LiteLLM

    with dropping_server() as url, pytest.raises(LMError):  # the first call imports litellm's clients: seconds
        LiteLLM("openai/local", api_base=url, max_retries=0).complete("warm up", max_tokens=2)
    with silent_server() as url:
        lm = LiteLLM("openai/local", api_base=url, timeout_s=2.0)
        t0 = time.monotonic()
        with pytest.raises(LMError) as err:
            lm.complete("hello", max_tokens=2)
        took = time.monotonic() - t0
    assert took < 3.5, f"gave up after {took:.1f} s with a 2 s timeout"
    msg = str(err.value)
    assert "Timeout" in msg and "request timeout is 2 s" in msg and "--lm-timeout" in msg and url in msg


def test_the_timeout_comes_from_the_environment(monkeypatch):
    from gift_llm.backends.litellm_backend import LiteLLM

    monkeypatch.setenv("GIFT_LM_TIMEOUT", "3.5")
    assert LiteLLM("openai/local", api_base="http://127.0.0.1:9/v1").timeout_s == 3.5
    monkeypatch.delenv("GIFT_LM_TIMEOUT")
    assert LiteLLM("openai/local", api_base="http://127.0.0.1:9/v1").timeout_s == 120.0
    monkeypatch.setenv("GIFT_LM_TIMEOUT", "soon")
    with pytest.raises(Exception, match="GIFT_LM_TIMEOUT='soon'"):
        LiteLLM("openai/local", api_base="http://127.0.0.1:9/v1")


def test_retries_are_logged_while_they_happen(caplog):
    from gift_llm.backends.litellm_backend import LiteLLM

    with dropping_server() as url, caplog.at_level(logging.WARNING, logger="gift_llm"):
        lm = LiteLLM("openai/local", api_base=url, timeout_s=20, max_retries=2, backoff_s=0.05)
        with pytest.raises(LMError, match="after 3 attempts"):
            lm.complete("hello", max_tokens=2)
    lines = [r.getMessage() for r in caplog.records if "retrying in" in r.getMessage()]
    assert len(lines) == 2 and "attempt 1 of 3" in lines[0] and "attempt 2 of 3" in lines[1], lines
    assert url in lines[0] and "request timeout left" in lines[0]


@pytest.mark.slow
def test_gift_lm_ask_lm_timeout_gives_a_clear_error_in_time():
    with silent_server() as url:
        t0 = time.monotonic()
        p = _gift("lm", "ask", "hello", "--lm", "litellm:openai/local", "--api-base", url, "--no-cache",
                  "--lm-timeout", "2", "--max-tokens", "2")
        took = time.monotonic() - t0
    assert p.returncode == 1 and "Traceback" not in p.stderr, p.stderr[-2000:]
    assert "gift lm: error: litellm openai/local" in p.stderr and "request timeout is 2 s" in p.stderr
    assert took < 60, f"{took:.0f} s"  # process start and the litellm import included
    p = _gift("lm", "ask", "hello", "--lm-timeout", "-1")
    assert p.returncode == 2 and "expected a positive number of seconds" in p.stderr


def test_every_command_that_takes_lm_takes_lm_timeout():
    from gift.cli import _parsers, build_parser

    with_lm = [p for p in _parsers(build_parser()) if any("--lm" in a.option_strings for a in p._actions)]
    assert len(with_lm) >= 4  # lm ask, align, evaluate-alignment, infer-intent, reproduce, demo
    for p in with_lm:
        assert any("--lm-timeout" in a.option_strings for a in p._actions), p.prog


# ----------------------------------------------------------------------------- secrets


@pytest.mark.slow
def test_credentials_in_api_base_reach_no_output_file_or_message(chat_server, tmp_path):
    """One run of every kind with a password and a query key in --api-base; then every byte it left is searched."""
    port = chat_server.server_address[1]
    base = f"http://user:{PASSWORD}@127.0.0.1:{port}/v1?api_key={QUERY_KEY}"
    env = {"GIFT_CACHE_DIR": str(tmp_path / "cache"), "GIFT_LM_RECORD": ""}
    record = tmp_path / "run.jsonl"
    outputs = []

    def run(*args: str, code: int = 0) -> subprocess.CompletedProcess:
        p = _gift(*args, env=env)
        outputs.extend([p.stdout, p.stderr])
        assert p.returncode == code, p.stderr[-3000:]
        return p

    first = json.loads(run("lm", "ask", "What is 2+2?", "--lm", "litellm:openai/test-model", "--api-base", base,
                           "--json", "--record", str(record)).stdout)
    assert first["text"] == "4" and first["stats"]["calls"] == 1
    assert first["lm"] == f"litellm:openai/test-model@http://user:***@127.0.0.1:{port}/v1?api_key=***"
    # the credentials did reach the server: redaction changes what is shown and keyed, not what is sent
    sent = chat_server.requests[0]
    auth = sent["headers"]["Authorization"]
    assert auth.startswith("Basic ") and base64.b64decode(auth[6:]).decode() == f"user:{PASSWORD}", sent
    assert QUERY_KEY in sent["path"], sent
    # another password for the same server: same redacted identity, so the answer comes from the cache
    other = base.replace(PASSWORD, "pw-OTHER-1234")
    second = json.loads(run("lm", "ask", "What is 2+2?", "--lm", "litellm:openai/test-model", "--api-base", other,
                            "--json").stdout)
    assert second["text"] == "4" and second["stats"]["hits"] == 1 and len(chat_server.requests) == 1
    stats = json.loads(run("lm", "cache-stats", "--json").stdout)
    assert stats["entries"] == 1 and stats["by_model"][0]["identity"] == first["lm"]
    run("lm", "cache-stats")
    # an error whose text echoes the URL and the credentials back
    failing = base.replace("/v1", "/fail/v1")
    p = run("lm", "ask", "What is 3+3?", "--lm", "litellm:openai/test-model", "--api-base", failing, code=1)
    assert "gift lm: error: litellm openai/test-model at http://user:***@" in p.stderr
    # a dead server: the connection error names the (redacted) URL
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        dead = base.replace(str(port), str(s.getsockname()[1]))
    run("lm", "ask", "What is 5+5?", "--lm", "litellm:openai/test-model", "--api-base", dead, "--no-cache",
        "--lm-timeout", "5", code=1)

    files = [f for f in (tmp_path / "cache").rglob("*") if f.is_file()] + [record]
    assert any(f.name.startswith("lm-cache.sqlite") for f in files) and record.stat().st_size > 0
    assert "127.0.0.1" in record.read_text() and "***" in record.read_text()
    for secret in (PASSWORD, QUERY_KEY):
        for i, text in enumerate(outputs):
            assert secret not in text, f"output {i} holds the secret:\n{text[-2000:]}"
        for f in files:
            assert secret.encode() not in f.read_bytes(), f"{f} holds the secret"


def test_redaction_rules():
    from gift.core.redaction import redact_text, redact_url, url_secrets

    assert redact_url("http://u:p4ss@h:1/v1?api_key=k123&api-version=2024") == \
        "http://u:***@h:1/v1?api_key=***&api-version=2024"
    assert redact_url("https://TOKEN123@h/v1") == "https://***@h/v1"
    assert redact_url("https://h/v1?X-Amz-Signature=abcd&token=t0k3n&model=m") == \
        "https://h/v1?X-Amz-Signature=***&token=***&model=m"
    assert redact_url("http://127.0.0.1:8080/v1") == "http://127.0.0.1:8080/v1"
    assert set(url_secrets("http://u:p4ss@h/v1?key=k123")) >= {"p4ss", "k123"}
    text = "POST http://u:p4ss@h/v1/chat failed: key k123 rejected"
    assert redact_text(text, url_secrets("http://u:p4ss@h/v1?key=k123")) == \
        "POST http://u:***@h/v1/chat failed: key *** rejected"


# ----------------------------------------------------------------------------- damaged cache files


def _scripted():
    sys.path.insert(0, str(Path(__file__).parent))
    from llm_scripted import ScriptedLM

    return ScriptedLM(answers=["first answer"])


def test_a_file_that_is_not_a_database_is_moved_aside_and_a_fresh_cache_started(tmp_path):
    from gift_llm.cache import CachedLM

    path = tmp_path / "lm-cache.sqlite"
    junk = b"this is not an SQLite file\n" * 200
    path.write_bytes(junk)
    lm = CachedLM(_scripted(), path=path)
    with pytest.warns(RuntimeWarning, match=r"is damaged \(file is not a database\); moved it to .*corrupt-"):
        assert lm.complete("hello").text == "first answer"
    kept = list(tmp_path.glob("lm-cache.sqlite.corrupt-*"))
    assert len(kept) == 1 and kept[0].read_bytes() == junk  # the old file is kept as it was
    assert lm.complete("hello").usage.cached and lm.inner.calls == 1  # the new cache works
    assert sqlite3.connect(path).execute("SELECT COUNT(*) FROM entries").fetchone()[0] == 1


@pytest.mark.slow
def test_gift_lm_cache_stats_survives_a_damaged_file_and_repair_checks_a_malformed_one(tmp_path):
    env = {"GIFT_CACHE_DIR": str(tmp_path)}
    path = tmp_path / "lm" / "lm-cache.sqlite"
    path.parent.mkdir()
    path.write_bytes(b"\x00garbage" * 512)
    p = _gift("lm", "cache-stats", env=env)
    assert p.returncode == 0 and "Traceback" not in p.stderr, p.stderr
    assert f"LM cache: {path} is damaged (file is not a database); moved it to {path}.corrupt-" in p.stderr
    assert p.stdout.startswith(f"{path}: 0 entries")

    # a real cache whose table pages were overwritten: opens fine, the full integrity check finds the damage
    for f in tmp_path.glob("lm/lm-cache.sqlite*"):
        if f.is_file():
            f.unlink()
    conn = sqlite3.connect(path)
    conn.execute("CREATE TABLE entries (key TEXT PRIMARY KEY, kind TEXT NOT NULL, identity TEXT NOT NULL, "
                 "request TEXT NOT NULL, response TEXT NOT NULL, created REAL NOT NULL)")
    conn.executemany("INSERT INTO entries VALUES (?, 'complete', 'x:y', '{}', ?, 0)",
                     [(f"k{i}", json.dumps({"text": "a" * 300})) for i in range(300)])
    conn.commit()
    conn.close()
    data = bytearray(path.read_bytes())
    page = 4096
    for start in range(2 * page, len(data) - page, 3 * page):  # trash a third of the pages after the header
        data[start + 8:start + 200] = os.urandom(192)
    path.write_bytes(bytes(data))
    p = _gift("lm", "cache-stats", "--repair", "--json", env=env)
    assert p.returncode == 0, p.stderr
    info = json.loads(p.stdout)
    assert info["repair"]["problem"] and info["repair"]["moved_to"].startswith(f"{path}.corrupt-")
    assert info["entries"] == 0 and Path(info["repair"]["moved_to"]).read_bytes() == bytes(data)
    p = _gift("lm", "cache-stats", "--repair", env=env)
    assert p.returncode == 0 and p.stdout.startswith("integrity check: ok"), p.stdout + p.stderr

