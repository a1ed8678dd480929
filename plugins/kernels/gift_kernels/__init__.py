"""gift_kernels plugin for gift."""
