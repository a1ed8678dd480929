"""What made a result: the code version, the git commit, file hashes (model files, suites).

- :func:`git_commit`: ``{"commit", "dirty"}`` of the checkout gift runs from (None outside git).
- :func:`code_version`: a hash of the Python sources of every loaded gift plugin distribution plus
  their versions; it changes when code that computes results changes, not when docs or tests do.
- :func:`file_sha256`: the SHA-256 of a file, remembered per (path, size, mtime) in the cache
  directory so a 1 GB model file is hashed once.
"""

from __future__ import annotations

import functools
import hashlib
import json
import os
import subprocess
import threading
from pathlib import Path
from typing import Any

_LOCK = threading.Lock()
_CHUNK = 8 << 20


def cache_dir() -> Path:
    """``$GIFT_CACHE_DIR`` or the user cache directory of gift."""
    root = os.environ.get("GIFT_CACHE_DIR")
    if not root:
        import platformdirs

        root = platformdirs.user_cache_dir("gift")
    return Path(root)


def file_sha256(path: str | os.PathLike) -> str:
    """SHA-256 of ``path`` (hex), read once per (path, size, mtime) and remembered in the cache directory."""
    p = Path(path).resolve()
    st = p.stat()
    key = f"{p}|{st.st_size}|{st.st_mtime_ns}"
    memo = cache_dir() / "file-hashes.json"
    with _LOCK:
        try:
            known = json.loads(memo.read_text(encoding="utf-8"))
        except (OSError, ValueError):
            known = {}
        if isinstance(known, dict) and isinstance(known.get(key), str):
            return known[key]
        h = hashlib.sha256()
        with open(p, "rb") as f:
            for chunk in iter(lambda: f.read(_CHUNK), b""):
                h.update(chunk)
        digest = h.hexdigest()
        known = known if isinstance(known, dict) else {}
        known[key] = digest
        try:
            memo.parent.mkdir(parents=True, exist_ok=True)
            tmp = memo.with_name(f"{memo.name}.{os.getpid()}.tmp")
            tmp.write_text(json.dumps(known), encoding="utf-8")
            tmp.replace(memo)
        except OSError:
            pass  # a read-only cache only costs a re-hash
        return digest


@functools.lru_cache(maxsize=1)
def git_commit() -> dict[str, Any] | None:
    """``{"commit": sha, "dirty": bool}`` of the git checkout that holds the gift package, or None."""
    here = Path(__file__).resolve().parent
    try:
        sha = subprocess.run(["git", "rev-parse", "HEAD"], cwd=here, capture_output=True, text=True,
                             timeout=10).stdout.strip()
        if not sha:
            return None
        status = subprocess.run(["git", "status", "--porcelain", "--untracked-files=no"], cwd=here,
                                capture_output=True, text=True, timeout=20).stdout
    except (OSError, subprocess.SubprocessError):
        return None
    return {"commit": sha, "dirty": bool(status.strip())}


def _package_files(package: str) -> list[Path]:
    import importlib.util

    try:
        spec = importlib.util.find_spec(package)
    except (ImportError, ValueError):
        return []
    if spec is None:
        return []
    if spec.submodule_search_locations:
        return sorted(p for loc in spec.submodule_search_locations for p in Path(loc).rglob("*.py")
                      if "__pycache__" not in p.parts)
    return [Path(spec.origin)] if spec.origin and spec.origin.endswith(".py") else []


@functools.lru_cache(maxsize=1)
def code_version() -> str:
    """A hash of the Python sources and versions of gift and of every installed gift plugin's package."""
    from importlib import metadata

    packages = {"gift": "gift"}
    for ep in metadata.entry_points(group="gift"):
        packages[ep.value.split(":")[0].split(".")[0]] = ep.dist.name if ep.dist is not None else "?"
    h = hashlib.sha256()
    for package in sorted(packages):
        try:
            h.update(f"{packages[package]}=={metadata.version(packages[package])}\n".encode())
        except (metadata.PackageNotFoundError, ValueError):
            pass
        for f in _package_files(package):
            h.update(f.name.encode())
            try:
                h.update(f.read_bytes())
            except OSError:
                continue
    return h.hexdigest()[:16]
