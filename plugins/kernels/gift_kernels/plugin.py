"""Entry point of gift_kernels: registers its kernels, the intent estimator and the component-level commands."""

from gift.plugins.hookspecs import hookimpl


@hookimpl
def gift_register_kernels(register):
    from gift_kernels.language import LanguageKernel
    from gift_kernels.lm_kernels import GiftProbKernel, MappingKernel, NoIntentMappingKernel
    from gift_kernels.vision import VisionKernel

    register(LanguageKernel, description="cosine of all-MiniLM-L6-v2 embeddings of names "
             "(use_descriptions=True: names + descriptions)")
    register(VisionKernel, description="cosine of EfficientNet-Lite0 features of three renders per object")
    register(MappingKernel, description="GIFT Call 3: LM maps test objects under the intent; K = vote "
             "share of N samples (default 10)")
    register(NoIntentMappingKernel, description="Call 3 without the intent (the paper's ablation)")
    register(GiftProbKernel, description="continuous GIFT kernel: LM log-odds that an object is what "
             "the goal is about, z-averaged with MiniLM description similarity")


@hookimpl
def gift_register_intent_estimators(register):
    from gift_kernels.intent import LMContrastiveIntentEstimator

    register(LMContrastiveIntentEstimator,
             description="GIFT Calls 1-2: motivations from preferred-vs-default traces, then semantic axes")


@hookimpl
def gift_register_commands(register):
    from gift_kernels import cli, intent_cli

    register("align", cli.run_align, help="align test objects to training objects with a kernel",
             configure=cli.configure_align)
    register("infer-intent", intent_cli.run_infer_intent, help="infer the intent (Calls 1-2) from saved "
             "demonstration pairs", configure=intent_cli.configure_infer_intent)


@hookimpl
def gift_register_doctor_checks(register):
    from gift_kernels import doctor

    register("embedding models", doctor.check_embedding_models, description="torch, MiniLM, EfficientNet-Lite0")
