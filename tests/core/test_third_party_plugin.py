"""A third-party plugin package (tests/plugin_packages/gift-toy-kernel) is built, pip-installed into a
fresh virtual environment, discovered by its entry point, and used by name in a pipeline step."""

import json
import site
import subprocess
import sys
import textwrap
import venv
from pathlib import Path

import pytest

PACKAGE = Path(__file__).parents[1] / "plugin_packages" / "gift-toy-kernel"

SCRIPT = textwrap.dedent("""
    import json
    import gift
    from gift.core.interfaces import AlignmentOperator
    from gift.core.data import Alignment, DISTRACTOR, ObjectSpec

    class ArgmaxAt(AlignmentOperator):
        name = "argmax-at"
        def align(self, kernel, test, train, intent=None, *, relevant_train=()):
            k = kernel.similarity(test, train, intent)
            mapping, scores = {}, {}
            for i, o in enumerate(test):
                j = int(k[i].argmax())
                mapping[o.name] = train[j].name if k[i, j] >= 0.2 else DISTRACTOR
                scores[o.name] = float(k[i, j])
            return Alignment(mapping, scores, threshold=0.2, kernel=kernel.name)

    comp = gift.get_manager().get("kernel", "toy-trigram")
    pipe = gift.GiftPipeline(kernel="toy-trigram", alignment=ArgmaxAt())
    al = pipe.align([ObjectSpec("toothbrush"), ObjectSpec("molding clay")],
                    [ObjectSpec("paintbrush"), ObjectSpec("banana")])
    print(json.dumps({"distribution": comp.distribution, "mapping": dict(al.mapping)}))
""")


@pytest.mark.slow
def test_third_party_kernel_package_installs_and_runs_by_name(tmp_path):
    env_dir = tmp_path / "venv"
    venv.EnvBuilder(with_pip=True).create(env_dir)
    py = env_dir / "bin" / "python"
    # The fresh venv sees the project's environment (gift and its dependencies) through a .pth hook,
    # but the toy plugin is installed into the fresh venv only.
    target_site = subprocess.check_output([py, "-c", "import sysconfig; print(sysconfig.get_paths()['purelib'])"],
                                          text=True).strip()
    ours = [p for p in site.getsitepackages() if p.endswith("site-packages")]
    Path(target_site, "zz_gift_project.pth").write_text(
        "".join(f"import site; site.addsitedir({p!r})\n" for p in ours))
    subprocess.run([py, "-m", "pip", "install", "-q", "--no-deps", "--no-build-isolation", "--no-index",
                    str(PACKAGE)], check=True, capture_output=True)
    # not visible from the project's own interpreter
    assert subprocess.run([sys.executable, "-c", "import gift_toy_kernel"], capture_output=True).returncode != 0
    out = subprocess.run([py, "-c", SCRIPT], check=True, capture_output=True, text=True).stdout
    result = json.loads(out.strip().splitlines()[-1])
    assert result["distribution"] == "gift-toy-kernel"
    assert result["mapping"] == {"toothbrush": "paintbrush", "molding clay": "distractor"}
    listed = subprocess.run([env_dir / "bin" / "python", "-m", "gift.cli", "plugins", "--json"], check=True,
                            capture_output=True, text=True).stdout
    names = {(c["kind"], c["name"], c["distribution"]) for c in json.loads(listed)["components"]}
    assert ("kernel", "toy-trigram", "gift-toy-kernel") in names
