"""gift_sim_drake: the Drake simulator of gift, one per registered robot (``drake-franka``, ``drake-jaco``,
``drake-<robot>`` for a plugin's arm), for the task families with a Drake motion family.

Public entry points (import from the submodules; most load Drake):

- :class:`gift_sim_drake.simulator.DrakeSimulator` (also ``gift.get_simulator("drake-franka")``):
  ``make_scene``, ``generate``, ``features``, ``render_object``, ``scene_model``;
- :mod:`gift_sim_drake.robots`: the arms of this package, :func:`~gift_sim_drake.robots.arm_kinematics`,
  :func:`~gift_sim_drake.robots.check_robot`; robots themselves are :class:`gift.core.robots.RobotSpec`;
- :mod:`gift_sim_drake.families`: :class:`~gift_sim_drake.families.MotionFamily` and
  :class:`~gift_sim_drake.families.ActionSet`, how a task family gets Drake scenes and motions;
  :mod:`gift_sim_drake.tabletop`: the four families of the paper;
- :func:`gift_sim_drake.checks.check_robot_on_drake`: a robot plugin's acceptance test;
- :func:`gift_sim_drake.features.compute_features`, :func:`~gift_sim_drake.features.trace_text` (no Drake needed);
- :func:`gift_sim_drake.datasets.save_dataset`, :func:`~gift_sim_drake.datasets.load_dataset`,
  :func:`~gift_sim_drake.datasets.generate_or_load`.
"""
