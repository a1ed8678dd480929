"""gift_sim_drake plugin for gift."""
