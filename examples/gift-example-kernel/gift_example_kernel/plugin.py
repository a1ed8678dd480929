"""The hooks of gift-example-kernel (named by the ``[project.entry-points.gift]`` line of its pyproject)."""

import gift


@gift.hookimpl
def gift_register_kernels(register):
    from gift_example_kernel.kernel import KeywordOverlapKernel

    register(KeywordOverlapKernel.name, KeywordOverlapKernel,
             description="weighted Jaccard of name/description keywords; intent keywords weigh more")
