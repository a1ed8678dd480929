"""Entry point of gift_kernels: registers its components with gift."""

from gift.plugins.hookspecs import hookimpl


@hookimpl
def gift_register_kernels(register):
    from gift_kernels.language import LanguageKernel
    from gift_kernels.vision import VisionKernel

    register("language", LanguageKernel, description="cosine of all-MiniLM-L6-v2 embeddings of names "
             "(use_descriptions=True: names + descriptions)")
    register("vision", VisionKernel, description="cosine of EfficientNet-Lite0 features of three renders per object")


@hookimpl
def gift_register_alignment_operators(register):
    from gift_kernels.alignment import ArgmaxThresholdAlignment

    register("argmax-threshold", ArgmaxThresholdAlignment,
             description="argmax over training objects, distractor below a threshold "
                         "(oracle | non-oracle | train-calibrated | float)")


@hookimpl
def gift_register_commands(register):
    from gift_kernels import cli

    register("align", cli.run_align, help="align test objects to training objects with a kernel",
             configure=cli.configure_align)
    register("evaluate-alignment", cli.run_evaluate_alignment,
             help="precision/recall/F1/AUC/FP/FN of kernels on a suite, per intent and per subset",
             configure=cli.configure_evaluate_alignment)
