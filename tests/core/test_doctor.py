"""``gift doctor``: passes on this install, and names what is missing or broken with its fix."""

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

import gift
import gift.cli
from gift.doctor import Check, check_cache_dirs, check_import, format_report, run_checks
from gift.plugins.manager import GiftPluginManager


def _doctor(*args: str, env: dict | None = None) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "gift.cli", "doctor", *args], capture_output=True, text=True,
                          env={**os.environ, **(env or {})}, timeout=600)


@pytest.mark.slow
def test_doctor_passes_on_this_install():
    proc = _doctor()
    assert proc.returncode == 0, proc.stdout + proc.stderr
    lines = proc.stdout.splitlines()
    assert not [ln for ln in lines if ln.startswith("FAIL")]
    for name in ("embedded model", "llama.cpp backend", "llama.cpp decodes", "drake", "EGL (headless renders)", "torch",
                 "MiniLM (language kernel)", "EfficientNet-Lite0 (vision kernel)", "cache directories", "plugins"):
        assert any(ln.startswith("ok") and f"  {name}  " in ln for ln in lines), (name, proc.stdout)
    assert "sha256 cc324af070c2... as expected" in proc.stdout  # the model file was hashed, not just stat'ed
    assert lines[-1].startswith("the install is complete")


def _fake_distribution(root: Path, module: str) -> None:
    """An installed distribution (dist-info on sys.path) whose gift entry point names a module that does not exist."""
    info = root / "broken_gift_plugin-0.1.dist-info"
    info.mkdir(parents=True)
    (info / "METADATA").write_text("Metadata-Version: 2.1\nName: broken-gift-plugin\nVersion: 0.1\n")
    (info / "entry_points.txt").write_text(f"[gift]\nbroken_plugin = {module}.plugin\n")


@pytest.mark.slow
def test_doctor_reports_a_plugin_that_fails_to_import(tmp_path):
    _fake_distribution(tmp_path / "site", "gift_no_such_module_xyz")
    env = {"PYTHONPATH": os.pathsep.join([str(tmp_path / "site"), os.environ.get("PYTHONPATH", "")]),
           "GIFT_PLUGINS": "broken_plugin,gift_llm"}  # keep it quick: only the LM plugin's checks besides
    proc = _doctor("--json", "--quick", env=env)
    assert proc.returncode == 1, proc.stdout + proc.stderr
    checks = {c["name"]: c for c in json.loads(proc.stdout)["checks"]}
    broken = checks["plugin broken_plugin"]
    assert broken["status"] == "fail"
    assert "broken-gift-plugin" in broken["detail"] and "ModuleNotFoundError" in broken["detail"]
    assert "gift_no_such_module_xyz" in broken["fix"] and "GIFT_DISABLE_PLUGINS=broken_plugin" in broken["fix"]
    assert checks["embedded model"]["status"] == "ok"  # the other checks still ran
    assert checks["plugins"]["detail"].startswith("1 loaded: gift_llm")


def _model_checks(results: list[Check]) -> Check:
    (model,) = [r for r in results if r.name == "embedded model"]
    return model


@pytest.mark.slow
def test_doctor_reports_a_wrong_model_file(tmp_path, monkeypatch, capsys):
    from gift_llm import embedded
    from gift_llm.doctor import check_embedded_model

    monkeypatch.setenv("GIFT_CACHE_DIR", str(tmp_path))
    path = tmp_path / "models" / embedded.MODEL_FILENAME
    path.parent.mkdir()
    path.write_bytes(b"GGUF but cut short")
    model = _model_checks(run_checks(gift.get_manager(), quick=True))
    assert model.status == "fail" and f"{len(b'GGUF but cut short')} bytes" in model.detail
    assert model.fix == "gift lm install --force"
    # through the command: exit 1, the fix printed under the failing line
    assert gift.cli.main(["doctor", "--quick"]) == 1
    out = capsys.readouterr().out
    assert "FAIL  embedded model" in out and "fix: gift lm install --force" in out

    with open(path, "r+b") as f:  # the right size, the wrong bytes (sparse: no 1 GB write)
        f.truncate(embedded.EXPECTED_SIZE)
    model = check_embedded_model(quick=True)  # no verification marker: hashed even with --quick
    assert model.status == "fail" and f"expected {embedded.EXPECTED_SHA256}" in model.detail
    assert model.fix == "gift lm install --force"

    path.unlink()  # not assembled yet, but the part packages are installed: assembled on first use
    model = check_embedded_model(quick=True)
    assert model.status == "warn" and model.fix == "gift lm install"


def test_unwritable_cache_dir_fails(tmp_path, monkeypatch):
    blocker = tmp_path / "a-file"
    blocker.write_text("not a directory")
    monkeypatch.setenv("GIFT_CACHE_DIR", str(blocker / "cache"))
    (check,) = check_cache_dirs()
    assert check.status == "fail" and str(blocker / "cache") in check.detail and "GIFT_CACHE_DIR" in check.fix
    monkeypatch.setenv("GIFT_CACHE_DIR", str(tmp_path / "fresh"))
    (check,) = check_cache_dirs()
    assert check.status == "ok"


def test_missing_module_is_a_failure_when_required_and_a_warning_when_optional():
    required = check_import("thing", ["json", "gift_no_such_module_xyz"], fix="pip install thing")
    assert required.status == "fail" and "gift_no_such_module_xyz" in required.detail
    assert required.fix == "pip install thing"
    optional = check_import("thing", ["gift_no_such_module_xyz"], fix="pip install thing", required=False)
    assert optional.status == "warn"
    assert check_import("json", ["json"], fix="").status == "ok"
    report = format_report([required, optional])
    assert "FAIL  thing" in report and "fix: pip install thing" in report
    assert report.splitlines()[-1].startswith("1 required item(s) missing")


class _PluginWithChecks:
    @gift.hookimpl
    def gift_register_doctor_checks(self, register):
        register("good", lambda quick=False: Check("good", "ok", "fine"))
        register("raises", self.raises)
        register("wrong type", lambda quick=False: "all good")

    @staticmethod
    def raises(quick=False):
        raise RuntimeError("boom")


def test_plugin_checks_run_and_a_broken_check_is_reported():
    manager = GiftPluginManager().load(entry_points=[])
    manager.register_plugin(_PluginWithChecks(), name="checks_plugin", distribution="gift-checks")
    by_name = {r.name: r for r in run_checks(manager, quick=True)}
    assert by_name["good"].status == "ok"
    assert by_name["raises"].status == "fail" and "'gift-checks' raised RuntimeError: boom" in by_name["raises"].detail
    assert by_name["wrong type"].status == "fail"
    assert by_name["python"].status == "ok" and by_name["plugins"].detail.startswith("1 loaded: checks_plugin")
    # doctor checks are listed by `gift plugins --all` only
    assert [c.name for c in manager.components("doctor_check")] == ["good", "raises", "wrong type"]
