"""gift_rewards plugin for gift."""
