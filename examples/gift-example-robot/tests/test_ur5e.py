"""The UR5e on the real Drake simulator, tested with gift's plugin-author fixtures."""

import numpy as np
import pytest

import gift
from gift_example_robot import UR5E


@pytest.fixture
def drake(gift_plugin_manager):
    if "drake-ur5e" not in gift_plugin_manager.names("simulator"):
        pytest.skip("no drake-ur5e: the Drake simulator (gift-sim-drake) is not installed in this environment")
    return gift.get_simulator("drake-ur5e")


def test_robot_is_discovered_through_its_entry_point(gift_plugin_manager):
    component = gift_plugin_manager.get("robot", "ur5e")
    assert component.distribution == "gift-example-robot"
    assert gift.get_robot("ur5e") == UR5E
    assert UR5E.urdf_path.is_file() and UR5E.dof == 6  # the URDF ships inside the package


@pytest.mark.drake
def test_ur5e_passes_the_drake_acceptance_check(drake):
    from gift_sim_drake.checks import check_robot_on_drake

    report = check_robot_on_drake("ur5e", seeds=(0, 1), n=6)
    assert report["dof"] == 6 and report["fk_error_m"] < 1e-9
    assert set(report["families"]) >= {"pack_backpack", "store_drawer", "sweep_spill", "place_mug"}
    assert all(row["unreachable_actions"] == 0 for row in report["families"].values())


@pytest.mark.drake
def test_ur5e_packs_the_relevant_objects_on_the_plant(drake, tiny_objects):
    train, _, _ = tiny_objects
    scene = drake.make_scene("pack_backpack", train, ["paintbrush"], seed=4)
    batch = drake.generate(scene, "preferred", 4, seed=0)
    assert batch.joint_positions.shape == (4, 61, 6) and set(batch.meta["acted_on"]) == {"paintbrush"}
    model = drake.scene_model(scene)  # the real MultibodyPlant: table, UR5e, backpack, objects
    backpack = np.asarray(scene.landmarks["backpack"])
    for q in batch.joint_positions[:, -1]:
        model.set_state(q, {})
        assert np.linalg.norm(model.ee_position() - backpack) < 0.02  # the tool centre point is in the backpack
