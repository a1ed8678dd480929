"""Plugin discovery, registration conflicts, broken plugins, allow/deny lists, lookup."""

import importlib.metadata
import json
import sys
import textwrap

import pytest

import gift
from gift.cli import main
from gift.core.errors import PluginError, UnknownComponentError
from gift.plugins.manager import GiftPluginManager, PluginWarning

KERNEL_PLUGIN = """
import numpy as np
import gift
from gift.core.interfaces import SimilarityKernel

class Const(SimilarityKernel):
    '''Every pair is {value} similar.'''
    name = "{name}"
    def similarity(self, test, train, intent=None):
        return np.full((len(test), len(train)), {value})

@gift.hookimpl
def gift_register_kernels(register):
    register("{name}", Const)
"""


@pytest.fixture
def plugin_dir(tmp_path, monkeypatch):
    monkeypatch.syspath_prepend(str(tmp_path))
    yield tmp_path
    for mod in [m for m in sys.modules if m.startswith("tp_")]:
        del sys.modules[mod]


def make_plugin(dir_, module, text):
    (dir_ / f"{module}.py").write_text(textwrap.dedent(text))
    return importlib.metadata.EntryPoint(name=module, value=module, group="gift")


def test_components_register_and_build_by_name(plugin_dir):
    ep = make_plugin(plugin_dir, "tp_const", KERNEL_PLUGIN.format(name="const-half", value=0.5))
    m = GiftPluginManager().load([ep])
    comp = m.get("kernel", "const-half")
    assert comp.plugin == "tp_const"
    assert comp.description == "Every pair is 0.5 similar."
    k = m.create("kernel", "const-half")
    assert k.similarity([gift.ObjectSpec("a")], [gift.ObjectSpec("b"), gift.ObjectSpec("c")]).tolist() == [[0.5, 0.5]]
    assert "pack_backpack" in m.names("task")  # built-in plugins always load
    with pytest.raises(UnknownComponentError, match="no kernel named 'nope'; registered: const-half"):
        m.get("kernel", "nope")
    with pytest.raises(PluginError, match="unknown component kind"):
        m.get("kernels", "x")


def test_duplicate_names_error_names_both_plugins(plugin_dir):
    a = make_plugin(plugin_dir, "tp_first", KERNEL_PLUGIN.format(name="same", value=0.1))
    b = make_plugin(plugin_dir, "tp_second", KERNEL_PLUGIN.format(name="same", value=0.2))
    with pytest.raises(PluginError) as err:
        GiftPluginManager().load([a, b])
    assert "'tp_first'" in str(err.value) and "'tp_second'" in str(err.value) and "kernel 'same'" in str(err.value)


def test_broken_plugin_warns_and_the_rest_keeps_working(plugin_dir):
    bad = make_plugin(plugin_dir, "tp_broken", "import a_module_that_does_not_exist\n")
    good = make_plugin(plugin_dir, "tp_good", KERNEL_PLUGIN.format(name="good", value=1.0))
    with pytest.warns(PluginWarning, match="'tp_broken'.*failed to import.*a_module_that_does_not_exist"):
        m = GiftPluginManager().load([bad, good])
    assert m.names("kernel") == ["good"]
    assert "tp_broken" in m.failed
    raising = make_plugin(plugin_dir, "tp_raising", """
        import gift
        @gift.hookimpl
        def gift_register_kernels(register):
            raise RuntimeError("boom")
    """)
    with pytest.warns(PluginWarning, match="'tp_raising'.*gift_register_kernels raised RuntimeError: boom"):
        m = GiftPluginManager().load([raising, good])
    assert m.names("kernel") == ["good"]


def test_allow_list_and_disable_list(plugin_dir, monkeypatch):
    a = make_plugin(plugin_dir, "tp_a", KERNEL_PLUGIN.format(name="ka", value=0.1))
    b = make_plugin(plugin_dir, "tp_b", KERNEL_PLUGIN.format(name="kb", value=0.2))
    monkeypatch.setenv("GIFT_PLUGINS", "tp_b")
    assert GiftPluginManager().load([a, b]).names("kernel") == ["kb"]
    monkeypatch.setenv("GIFT_PLUGINS", "")
    monkeypatch.setenv("GIFT_DISABLE_PLUGINS", "tp_b, tp_x")
    assert GiftPluginManager().load([a, b]).names("kernel") == ["ka"]


def test_installed_distributions_are_discovered_by_entry_point(fresh_plugins, monkeypatch):
    eps = {ep.name: ep.dist.name for ep in importlib.metadata.entry_points(group="gift")}
    assert {"gift_llm", "gift_kernels", "gift_rewards", "gift_sim_drake"} <= set(eps)
    monkeypatch.setenv("GIFT_DISABLE_PLUGINS", ",".join(eps))
    assert gift.list_components("kernel") == {}
    assert {c["name"] for c in gift.list_components("task")["task"]} == {
        "place_mug", "sweep_spill", "pack_backpack", "store_drawer"}


def test_cli_plugins_json_lists_components_with_distribution(fresh_plugins, capsys):
    assert main(["plugins", "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    by_kind = {}
    for c in data["components"]:
        by_kind.setdefault(c["kind"], []).append(c)
    assert {c["distribution"] for c in by_kind["task"]} == {"gift"}
    dists = {c["distribution"] for comps in by_kind.values() for c in comps}
    assert "gift" in dists
    assert main(["plugins"]) == 0
    assert "pack_backpack" in capsys.readouterr().out


OPTIONS_PLUGIN = """
import numpy as np
import gift
from gift.core.interfaces import SimilarityKernel

class Scaled(SimilarityKernel):
    name = "scaled"
    def __init__(self, scale, *, offset=0.0):
        self.scale, self.offset = scale, offset
    def similarity(self, test, train, intent=None):
        return np.full((len(test), len(train)), self.scale + self.offset)

@gift.hookimpl
def gift_register_kernels(register):
    register("scaled", Scaled)
"""


def test_unknown_or_missing_options_name_the_component_and_the_valid_options(plugin_dir):
    from gift.core.errors import ComponentOptionError

    m = GiftPluginManager().load([make_plugin(plugin_dir, "tp_opts", OPTIONS_PLUGIN)])
    assert m.create("kernel", "scaled", scale=0.5, offset=0.25).scale == 0.5
    assert m.get("kernel", "scaled").options() == ["scale", "offset"]
    with pytest.raises(ComponentOptionError) as err:
        m.create("kernel", "scaled", scale=0.5, nonsense=1, colour="red")
    assert str(err.value) == ("kernel 'scaled' (plugin 'tp_opts') has no options 'colour', 'nonsense'; "
                              "valid options: scale, offset")
    assert isinstance(err.value, TypeError)  # callers that caught the factory's TypeError still do
    with pytest.raises(ComponentOptionError, match=r"kernel 'scaled' .*missing a required argument: 'scale'; "
                                                   r"valid options: scale, offset"):
        m.create("kernel", "scaled")


def test_gift_align_lists_the_valid_options_of_a_kernel(capsys):
    code = main(["align", "--train", "paintbrush", "banana", "--test", "toothbrush", "--kernel",
                 "language:nonsense=1"])
    err = capsys.readouterr().err
    assert code == 1 and "Traceback" not in err
    assert "kernel 'language' (plugin 'gift_kernels') has no option 'nonsense'; valid options:" in err
    assert "use_descriptions" in err
