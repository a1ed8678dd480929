"""Threads of the llamacpp backend: the governor leaves cores busy with other work alone, and the thread
count never changes the model's logits."""

from __future__ import annotations

import numpy as np
import pytest

from gift.core.errors import LMError
from gift_llm.backends import llamacpp
from gift_llm.backends.llamacpp import ThreadGovernor


class Ticks:
    """A fake ``/proc``: each ``advance(others, own)`` adds a window of 100 ticks per CPU."""

    def __init__(self, cpus: int = 2) -> None:
        self.cpus, self.total, self.busy, self.own = cpus, 0, 0, 0

    def advance(self, others: float, own: float = 0.0) -> None:
        self.total += 100 * self.cpus
        self.busy += round(100 * (others + own))
        self.own += round(100 * own)

    def __call__(self):
        return self.total, self.busy, self.own


def test_governor_takes_the_cores_other_processes_leave_free(monkeypatch):
    ticks = Ticks(cpus=2)
    gov = ThreadGovernor(2, sample=ticks, cpus=2, min_interval_s=0.0)
    for others, own, want in [(0.0, 0.0, 2), (0.2, 1.8, 2), (0.4, 1.0, 2), (0.6, 0.5, 1), (1.0, 1.0, 1),
                              (1.9, 0.1, 1), (2.0, 0.0, 1), (0.1, 0.0, 2)]:
        ticks.advance(others, own)
        assert gov.next_threads() == want, (others, own)
        assert gov.others == pytest.approx(others, abs=0.01)
    # never above the process's budget (e.g. a local-executor worker with 1 thread)
    one = ThreadGovernor(1, sample=ticks, cpus=2, min_interval_s=0.0)
    ticks.advance(0.0)
    assert one.next_threads() == 1


def test_governor_reuses_a_decision_for_close_calls_and_falls_back_without_proc(monkeypatch):
    ticks = Ticks(cpus=4)
    gov = ThreadGovernor(4, sample=ticks, cpus=4, min_interval_s=3600.0)
    monkeypatch.setattr(llamacpp.os, "getloadavg", lambda: (2.2, 0.0, 0.0))
    ticks.advance(0.0)  # too short a window: the first call estimates from the load average
    assert gov.next_threads() == 2 and gov.others == pytest.approx(2.2)
    ticks.advance(4.0)
    assert gov.next_threads() == 2  # reused: the window is still too short
    blind = ThreadGovernor(3, sample=lambda: None, cpus=4, min_interval_s=0.0)
    assert blind.next_threads() == 3


def test_real_proc_sample_counts_this_process():
    a = llamacpp._cpu_ticks()
    x = 0
    for i in range(3_000_000):  # burn some CPU in this process
        x += i
    b = llamacpp._cpu_ticks()
    assert a is not None and b is not None
    assert b[0] >= a[0] and b[1] >= a[1] and b[2] > a[2]


def test_bad_thread_count_is_a_clear_error(tmp_path):
    with pytest.raises(LMError, match="n_threads must be >= 1"):
        llamacpp.LlamaCppLM(tmp_path / "m.gguf", n_threads=0)


@pytest.mark.slow
@pytest.mark.lm
def test_thread_count_does_not_change_a_bit_of_the_logits(embedded_lm):
    """The same prompt on 1 and on 2 threads gives identical logits, evaluated fresh and with the system
    message reused from the KV cache (and, by the evaluation schedule, fresh and reused agree too)."""
    system = {"role": "system", "content": "You answer questions about everyday objects with a single word: yes or no."}
    msgs = [system, {"role": "user", "content": "Is a paintbrush (a tool for applying paint) one of the art "
                                                "supplies? Answer yes or no."}]
    other = [system, {"role": "user", "content": "Is a stapler one of the art supplies? Answer yes or no."}]
    prompt = embedded_lm.chat_prompt(msgs)
    saved = embedded_lm._fixed_threads
    fresh, reused = {}, {}
    try:
        for n in (1, 2, 1):
            embedded_lm._fixed_threads = n
            with embedded_lm._lock:
                embedded_lm.llama.reset()
                fresh.setdefault(n, []).append(embedded_lm.next_token_logits(prompt))
                assert embedded_lm.last_reused_tokens == 0
                embedded_lm.llama.reset()
                embedded_lm.next_token_logits(embedded_lm.chat_prompt(other))  # shares the system prefix
                reused.setdefault(n, []).append(embedded_lm.next_token_logits(prompt))
                assert embedded_lm.last_reused_tokens == prompt.starts[0] > 10
            assert embedded_lm.last_threads == n
    finally:
        embedded_lm._fixed_threads = saved
    for got in (fresh, reused):
        np.testing.assert_array_equal(got[2][0], fresh[1][0])
        np.testing.assert_array_equal(got[1][1], fresh[1][0])
