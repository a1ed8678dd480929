"""gift-example-kernel: a third-party similarity kernel for gift (see docs/tutorials/kernel-plugin.md)."""

from gift_example_kernel.kernel import KeywordOverlapKernel, keywords

__all__ = ["KeywordOverlapKernel", "keywords"]
