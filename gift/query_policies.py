"""Built-in query policies (a built-in plugin): which test object to ask the human about next
(:mod:`gift.core.queries`)."""

from __future__ import annotations

from gift.core.queries import (DisagreementPolicy, ErrorBoundPolicy, ExpectedErrorPolicy, RandomPolicy,
                               UncertaintyPolicy)
from gift.plugins.hookspecs import hookimpl


@hookimpl
def gift_register_query_policies(register):
    register(UncertaintyPolicy, description="the object whose decision score is nearest the cut")
    register(DisagreementPolicy, description="the object the intent candidates (or the kernel's terms, e.g. "
                                             "gift-prob's LM and MiniLM) disagree on most")
    register(ErrorBoundPolicy, description="the object whose answer is expected to lower the error bound of "
                                           "the scene's trajectories most")
    register(ExpectedErrorPolicy, description="the object whose answer, re-scoring the scene, is expected to leave "
                                              "the fewest wrong decisions (expected error reduction)")
    register(RandomPolicy, description="an object drawn uniformly among those not asked yet (the baseline)")
