"""A scripted LM for control-flow unit tests only (cache bookkeeping, repair loop). Never a stand-in for a
feature shown working: those tests run the real embedded model."""

from __future__ import annotations

from gift.core.data import Completion, Usage
from gift.core.interfaces import LMBackend


class ScriptedLM(LMBackend):
    """Answers with ``answers`` in turn (the last one repeats); counts calls; remembers the prompts."""

    name = "scripted"
    supports_choice_probabilities = True

    def __init__(self, answers=("{'a': 1}",), model="script"):
        self.answers = list(answers)
        self.model = model
        self.calls = 0
        self.prompts = []

    def complete(self, messages, *, temperature=0.0, seed=None, max_tokens=512, stop=None, json_schema=None):
        self.prompts.append(list(messages))
        text = self.answers[min(self.calls, len(self.answers) - 1)]
        if seed is not None:
            text = f"{text} seed={seed}"
        self.calls += 1
        return Completion(text, Usage(prompt_tokens=10, completion_tokens=5, latency_s=0.01, cost_usd=0.002),
                          model=self.identity())

    def choice_probabilities(self, messages, choices):
        self.calls += 1
        return {c: 1.0 / len(choices) for c in choices}
