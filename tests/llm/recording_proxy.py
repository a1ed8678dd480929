"""A recording HTTP proxy for the litellm tests: it keeps every request body it forwards to a real server.

litellm talks HTTP to the proxy, the proxy to ``llama_cpp.server`` on the embedded model, so a test sees
exactly what went over the wire and gets the real model's answer. ``rewrite`` may change a body before it
is forwarded (llama_cpp.server accepts structured output only as ``{"type": "json_object", "schema": ...}``).
"""

from __future__ import annotations

import json
import threading
import urllib.error
import urllib.request
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from typing import Any


@contextmanager
def recording_proxy(upstream: str, rewrite: Callable[[dict], dict] | None = None
                    ) -> Iterator[tuple[str, list[dict[str, Any]]]]:
    """Serve at 127.0.0.1:<free port>; yields (base URL ending in the upstream's path, exchanges): one
    ``{"request": body as sent by the client, "status": int, "response": parsed JSON answer}`` per POST."""
    from urllib.parse import urlsplit

    up = urlsplit(upstream)
    exchanges: list[dict[str, Any]] = []

    class Handler(BaseHTTPRequestHandler):
        def _forward(self, data: bytes | None) -> tuple[int, bytes]:
            req = urllib.request.Request(f"{up.scheme}://{up.netloc}{self.path}", data=data, method=self.command,
                                         headers={"Content-Type": "application/json"})
            try:
                with urllib.request.urlopen(req, timeout=600) as r:
                    status, payload, ctype = r.status, r.read(), r.headers.get("Content-Type", "application/json")
            except urllib.error.HTTPError as e:
                status, payload, ctype = e.code, e.read(), "application/json"
            self.send_response(status)
            self.send_header("Content-Type", ctype)
            self.send_header("Content-Length", str(len(payload)))
            self.end_headers()
            self.wfile.write(payload)
            return status, payload

        def do_GET(self) -> None:  # noqa: N802 - http.server's naming
            self._forward(None)

        def do_POST(self) -> None:  # noqa: N802
            body = json.loads(self.rfile.read(int(self.headers.get("Content-Length", 0))) or b"{}")
            status, payload = self._forward(json.dumps(rewrite(body) if rewrite else body).encode())
            try:
                answer = json.loads(payload)
            except ValueError:
                answer = payload.decode("utf-8", "replace")
            exchanges.append({"request": body, "status": status, "response": answer})

        def log_message(self, *args: Any) -> None:
            pass

    server = ThreadingHTTPServer(("127.0.0.1", 0), Handler)
    thread = threading.Thread(target=server.serve_forever, daemon=True)
    thread.start()
    try:
        yield f"http://127.0.0.1:{server.server_address[1]}{up.path}", exchanges
    finally:
        server.shutdown()
        server.server_close()
