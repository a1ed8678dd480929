"""gift_llm plugin for gift."""
