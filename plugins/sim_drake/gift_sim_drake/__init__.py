"""gift_sim_drake: Drake simulators (Franka Panda, Kinova Jaco) for gift's four task families.

Public entry points (import from the submodules; they load Drake):

- :class:`gift_sim_drake.simulator.DrakeFranka`, :class:`~gift_sim_drake.simulator.DrakeJaco`
  (also ``gift.get_simulator("drake-franka")``): ``make_scene``, ``generate``, ``features``, ``render_object``;
- :func:`gift_sim_drake.features.compute_features`, :func:`~gift_sim_drake.features.trace_text` (no Drake needed);
- :func:`gift_sim_drake.datasets.save_dataset`, :func:`~gift_sim_drake.datasets.load_dataset`,
  :func:`~gift_sim_drake.datasets.generate_or_load`.
"""
