"""Figures (PNG), ``report.md`` and ``results.json`` of a study (``gift reproduce``, ``gift demo``), and the
text tables of ``gift evaluate-alignment``.

Results layout of a study (every number of a run; figures read only this; NaN is written as null)::

    {"config": {...}, "manifest": {"git", "code_version", "lm": {"identity", "model_sha256", "usage"}, "suite",
                                   "runs": [one record per run or resume]},
     "timing": {stage: seconds},
     "intents": {intent: {"text", "motivations", "axes", "source"}},
     "relevant": {intent: {"names", "source", ...}},
     "alignment": {intent: {kernel: {"thresholds": {thr: {"cut", "note", "mapping", "scores", "metrics"}},
                                     "objects": {object: {"decision", "match"}}, "fallbacks", "details"}}},
     "sanity": {intent: {"inferred": [mean, se], "generic": [mean, se], "texts": [...]}},
     "rq1":    {intent: {kernel: {"mean": m, "se": s, "per_seed": [...]}}},
     "rq2":    {intent: {kernel: {threshold: {subset: {"f1", "fp", "fn", "fp_rate", "fn_rate", "auc", "n"}}}}},
     "scatter": {intent: {"anchor": name, "points": [{"object", "language", "vision", "relevant"}]}},
     "rq3":    {intent: {kernel: {"objects": [...], "relevant": [...], "mean": [...], "se": [...]}}}}

``results.json`` is strict JSON (:func:`gift.core.serialization.write_json`): a number that is not defined
(the AUC of a subset whose objects are all relevant or all irrelevant) is ``null``, and the means below skip it.
``report.html`` (:mod:`gift_experiments.html_report`) reads the same dictionary and the output folder.
"""

from __future__ import annotations

import json
import logging
import math
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from gift.core.serialization import finite_values, write_json
from gift.study.chain import REPORT_SUBSETS

log = logging.getLogger("gift.report")

KERNEL_ORDER = ("vision", "language", "lm-no-intent", "gift", "gift-prob")
SUBSET_LABEL = {"R": "S_R", "lang": "S_lang", "vis": "S_vis", "unk": "S_unk", "all": "S_R ∪ S_conf"}


def _kernels(block: dict[str, dict]) -> list[str]:
    names = {k for per in block.values() for k in per}
    return [k for k in KERNEL_ORDER if k in names] + sorted(names - set(KERNEL_ORDER))


def _plt():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def _num(x: Any) -> float:
    """A plotted number: ``null`` (None) and missing values are NaN (matplotlib leaves them out)."""
    return float("nan") if x is None else float(x)


def _grouped_bars(ax, groups: list[str], series: list[str], mean: np.ndarray, se: np.ndarray | None) -> None:
    """``mean``/``se``: ``[n_series, n_groups]``."""
    mean = np.vectorize(_num, otypes=[float])(mean)
    se = None if se is None else np.vectorize(_num, otypes=[float])(se)
    width = 0.8 / max(len(series), 1)
    x = np.arange(len(groups))
    for k, name in enumerate(series):
        ax.bar(x + (k - (len(series) - 1) / 2) * width, mean[k], width, label=name,
               yerr=None if se is None else se[k], capsize=2, ecolor="black")
    ax.set_xticks(x, groups, rotation=20, ha="right")
    ax.legend(fontsize=7)


def plot_win_rate(results: dict, out: Path) -> Path | None:
    rq1 = results.get("rq1") or {}
    if not rq1:
        return None
    plt = _plt()
    intents, kernels = list(rq1), _kernels(rq1)
    mean = np.array([[rq1[i].get(k, {}).get("mean", np.nan) for i in intents] for k in kernels])
    se = np.array([[rq1[i].get(k, {}).get("se", 0.0) for i in intents] for k in kernels])
    fig, ax = plt.subplots(figsize=(7, 3.2))
    _grouped_bars(ax, intents, kernels, mean, se)
    ax.axhline(0.5, color="grey", lw=0.8, ls="--")
    ax.set_ylim(0, 1)
    ax.set_ylabel("pairwise win rate")
    ax.set_title("RQ1: test-time win rate of the aligned reward (± s.e. over seeds)")
    return _save(fig, out / "win_rate.png")


def plot_f1(results: dict, out: Path, threshold: str) -> Path | None:
    rq2 = results.get("rq2") or {}
    if not rq2:
        return None
    plt = _plt()
    intents, kernels = list(rq2), _kernels(rq2)
    mean = np.array([[rq2[i].get(k, {}).get(threshold, {}).get("all", {}).get("f1", np.nan) for i in intents]
                     for k in kernels])
    fig, ax = plt.subplots(figsize=(7, 3.2))
    _grouped_bars(ax, intents, kernels, mean, None)
    ax.set_ylim(0, 1)
    ax.set_ylabel("alignment F1")
    ax.set_title(f"RQ2: state-alignment F1 on S_R ∪ S_conf ({threshold} threshold)")
    return _save(fig, out / f"f1_{threshold}.png")


def plot_confounds(results: dict, out: Path, threshold: str) -> Path | None:
    """FP % and FN % per confound subset, summed over the intents that have confound sets."""
    rq2 = results.get("rq2") or {}
    kernels = _kernels(rq2) if rq2 else []
    subsets = ["lang", "vis", "unk"]
    counts = {k: {s: np.zeros(4) for s in subsets} for k in kernels}  # fp, neg, fn, pos
    for per in rq2.values():
        for k in kernels:
            for s in subsets:
                m = per.get(k, {}).get(threshold, {}).get(s)
                if m:
                    counts[k][s] += [m["fp"], m["fp"] + m["tn"], m["fn"], m["fn"] + m["tp"]]
    if not any(c[s][1] + c[s][3] for c in counts.values() for s in subsets):
        return None
    plt = _plt()
    fig, axes = plt.subplots(1, 2, figsize=(9, 3.2))
    for ax, (label, num, den) in zip(axes, (("FP %", 0, 1), ("FN %", 2, 3))):
        mean = np.array([[100 * counts[k][s][num] / counts[k][s][den] if counts[k][s][den] else np.nan
                          for s in subsets] for k in kernels])
        _grouped_bars(ax, [SUBSET_LABEL[s] for s in subsets], kernels, mean, None)
        ax.set_ylim(0, 100)
        ax.set_ylabel(label)
    fig.suptitle(f"RQ2: errors on the confounding states ({threshold} threshold)")
    return _save(fig, out / f"confounds_{threshold}.png")


def place_labels(ax, xs: Sequence[float], ys: Sequence[float], labels: Sequence[str], fontsize: float = 6.5,
                 avoid: Sequence[tuple[float, float]] = ()) -> list:
    """Annotate each point ``(xs[i], ys[i])`` with ``labels[i]`` where the label overlaps no other label and no
    point (greedy, in order of crowdedness; candidates on rings of growing radius around the point, joined
    to it by a thin leader line when away from it). Returns the text artists."""
    fig = ax.figure
    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    to_disp = ax.transData.transform
    pts = to_disp(np.column_stack([xs, ys])) if len(xs) else np.zeros((0, 2))
    obstacles = [to_disp(np.asarray(avoid, dtype=float))] if len(avoid) else []
    blocked = np.concatenate([pts] + obstacles) if obstacles else pts
    frame = ax.get_window_extent(renderer)
    r_pt = 4.0 * fig.dpi / 72.0  # marker radius (display px)
    placed: list[tuple[float, float, float, float]] = []
    artists = [None] * len(labels)
    crowd = [int(np.sum(np.hypot(*(pts - p).T) < 40 * fig.dpi / 72)) for p in pts]
    px = fig.dpi / 72.0
    for i in sorted(range(len(labels)), key=lambda i: -crowd[i]):
        probe = ax.text(0, 0, labels[i], fontsize=fontsize)
        bb = probe.get_window_extent(renderer)
        probe.remove()
        w, h = bb.width, bb.height
        best = None
        for radius in (5, 10, 16, 24, 34, 46, 60, 76):
            for ang in np.deg2rad([30, -30, 150, -150, 90, -90, 0, 180, 60, -60, 120, -120]):
                dx, dy = np.cos(ang) * radius * px, np.sin(ang) * radius * px
                cx, cy = pts[i, 0] + dx, pts[i, 1] + dy
                x0 = cx if np.cos(ang) >= -1e-9 else cx - w
                x0 = cx - w / 2 if abs(np.cos(ang)) < 1e-6 else x0
                y0 = cy if np.sin(ang) >= 0 else cy - h
                box = (x0 - 1, y0 - 1, x0 + w + 1, y0 + h + 1)
                if box[0] < frame.x0 or box[2] > frame.x1 or box[1] < frame.y0 or box[3] > frame.y1:
                    continue
                if any(not (box[2] < b[0] or box[0] > b[2] or box[3] < b[1] or box[1] > b[3]) for b in placed):
                    continue
                near = (blocked[:, 0] > box[0] - r_pt) & (blocked[:, 0] < box[2] + r_pt) & \
                       (blocked[:, 1] > box[1] - r_pt) & (blocked[:, 1] < box[3] + r_pt)
                if near.any():
                    continue
                best = (box, radius)
                break
            if best:
                break
        if best is None:  # nowhere free: the first candidate, overlapping (never silently dropped)
            box, radius = (pts[i, 0] + 5 * px, pts[i, 1] + 5 * px, pts[i, 0] + 5 * px + w, pts[i, 1] + 5 * px + h), 5
        else:
            box, radius = best
        placed.append(box)
        x, y = ax.transData.inverted().transform((box[0] + 1, box[1] + 1))
        artists[i] = ax.annotate(labels[i], (xs[i], ys[i]), xytext=(x, y), textcoords="data", fontsize=fontsize,
                                 ha="left", va="bottom",
                                 arrowprops=dict(arrowstyle="-", lw=0.5, color="0.35", shrinkA=0, shrinkB=2)
                                 if radius > 5 else None)
    return artists


def plot_scatter(results: dict, out: Path) -> list[Path]:
    paths = []
    plt = _plt()
    for intent, block in (results.get("scatter") or {}).items():
        pts = block.get("points") or []
        if not pts:
            continue
        fig, ax = plt.subplots(figsize=(6.4, 5.6))
        xs = np.array([p["language"] for p in pts] + [1.0])
        ys = np.array([p["vision"] for p in pts] + [1.0])
        ax.scatter(xs[:-1], ys[:-1], c=["tab:green" if p["relevant"] else "tab:red" for p in pts], s=16, zorder=3)
        ax.scatter([1.0], [1.0], marker="*", s=120, c="black", zorder=3)
        pad_x, pad_y = 0.12 * max(np.ptp(xs), 0.05), 0.12 * max(np.ptp(ys), 0.05)
        ax.set_xlim(xs.min() - pad_x, xs.max() + pad_x)
        ax.set_ylim(ys.min() - pad_y, ys.max() + pad_y)
        ax.set_xlabel("language similarity to anchor")
        ax.set_ylabel("vision similarity to anchor")
        ax.set_title(f"{intent}: green = relevant, red = not", fontsize=8)
        fig.tight_layout()
        place_labels(ax, xs, ys, [p["object"] for p in pts] + [f"anchor: {block['anchor']}"])
        paths.append(_save(fig, out / f"scatter_{intent}.png", tight=False))
    return paths


def plot_boltzmann(results: dict, out: Path) -> list[Path]:
    paths = []
    plt = _plt()
    for intent, per in (results.get("rq3") or {}).items():
        kernels = [k for k in KERNEL_ORDER if k in per] + sorted(set(per) - set(KERNEL_ORDER))
        if not kernels:
            continue
        objects = per[kernels[0]]["objects"]
        labels = [f"{o}{' *' if r else ''}" for o, r in zip(objects, per[kernels[0]]["relevant"])]
        mean = np.array([per[k]["mean"] for k in kernels])
        se = np.array([per[k]["se"] for k in kernels])
        fig, ax = plt.subplots(figsize=(7, 3.2))
        _grouped_bars(ax, labels, kernels, mean, se)
        ax.set_ylim(0, 1)
        ax.set_ylabel("Boltzmann probability")
        ax.set_title(f"RQ3 ({intent}): choice among candidates (* = relevant object)", fontsize=9)
        paths.append(_save(fig, out / f"boltzmann_{intent}.png"))
    return paths


def plot_intent_cosine(results: dict, out: Path) -> Path | None:
    sanity = results.get("sanity") or {}
    if not sanity:
        return None
    plt = _plt()
    intents = list(sanity)
    mean = np.array([[sanity[i]["inferred"][0] for i in intents], [sanity[i]["generic"][0] for i in intents]])
    se = np.array([[sanity[i]["inferred"][1] for i in intents], [sanity[i]["generic"][1] for i in intents]])
    fig, ax = plt.subplots(figsize=(7, 3.2))
    _grouped_bars(ax, intents, ["LM-inferred intent", "generic intent"], mean, se)
    ax.set_ylim(0, 1)
    ax.set_ylabel("cosine to ground-truth intent")
    ax.set_title("Sanity check: inferred vs ground-truth intent (MiniLM cosine)")
    return _save(fig, out / "intent_cosine.png")


def _save(fig, path: Path, tight: bool = True) -> Path:
    if tight:
        fig.tight_layout()
    fig.savefig(path, dpi=130)
    import matplotlib.pyplot as plt

    plt.close(fig)
    return path


def make_figures(results: dict, out: Path) -> list[Path]:
    out.mkdir(parents=True, exist_ok=True)
    paths: list[Path | None] = [plot_win_rate(results, out), plot_intent_cosine(results, out)]
    for th in _thresholds(results):
        paths += [plot_f1(results, out, th), plot_confounds(results, out, th)]
    paths += plot_scatter(results, out) + plot_boltzmann(results, out)
    return [p for p in paths if p is not None]


def _thresholds(results: dict) -> list[str]:
    seen: dict[str, None] = {}
    for per in (results.get("rq2") or {}).values():
        for by_th in per.values():
            seen.update(dict.fromkeys(by_th))
    return list(seen)


def _fmt(m: float, se: float | None = None) -> str:
    if m is None or (isinstance(m, float) and np.isnan(m)):
        return "–"
    return f"{m:.3f}" if se is None else f"{m:.3f} ± {se:.3f}"


def win_rate_table(results: dict) -> str:
    rq1 = results.get("rq1") or {}
    if not rq1:
        return ""
    kernels = _kernels(rq1)
    rows = ["| intent | " + " | ".join(kernels) + " |", "|---" * (len(kernels) + 1) + "|"]
    for intent, per in rq1.items():
        rows.append(f"| {intent} | " + " | ".join(_fmt(per[k]["mean"], per[k]["se"]) if k in per else "–"
                                                  for k in kernels) + " |")
    means = {k: finite_values(per[k]["mean"] for per in rq1.values() if k in per) for k in kernels}
    rows.append("| **mean** | " + " | ".join(_fmt(float(np.mean(v))) if v else "–" for v in means.values()) + " |")
    return "\n".join(rows)


def f1_table(results: dict, threshold: str, subset: str = "all") -> str:
    rq2 = results.get("rq2") or {}
    if not rq2:
        return ""
    kernels = _kernels(rq2)
    rows = ["| intent | " + " | ".join(kernels) + " |", "|---" * (len(kernels) + 1) + "|"]
    for intent, per in rq2.items():
        cells = []
        for k in kernels:
            m = per.get(k, {}).get(threshold, {}).get(subset)
            cells.append(f"{m['f1']:.2f} (AUC {m['auc']:.2f})" if m and finite_values([m.get("auc")])
                         else (f"{m['f1']:.2f}" if m else "–"))
        rows.append(f"| {intent} | " + " | ".join(cells) + " |")
    return "\n".join(rows)


def headline_table(runs: dict[str, dict], threshold: str = "train-calibrated") -> str:
    """Markdown: one row per kernel; per run (e.g. per robot) the RQ1 win rate (mean over intents ± SE
    over intents) and the RQ2 alignment F1 on S_R ∪ S_conf (mean over intents) at ``threshold``."""
    kernels: list[str] = []
    for res in runs.values():
        for k in _kernels(res.get("rq1") or {}) + _kernels(res.get("rq2") or {}):
            if k not in kernels:
                kernels.append(k)
    kernels = [k for k in KERNEL_ORDER if k in kernels] + [k for k in kernels if k not in KERNEL_ORDER]
    head = "| kernel | " + " | ".join(f"win rate ({r}) | F1 ({r})" for r in runs) + " |"
    rows = [head, "|---" * (1 + 2 * len(runs)) + "|"]
    for k in kernels:
        cells = []
        for res in runs.values():
            wr = finite_values(per[k]["mean"] for per in (res.get("rq1") or {}).values() if k in per)
            f1 = finite_values(per[k][threshold]["all"]["f1"] for per in (res.get("rq2") or {}).values()
                               if threshold in per.get(k, {}) and "all" in per[k][threshold])
            se = float(np.std(wr, ddof=1) / np.sqrt(len(wr))) if len(wr) > 1 else None
            cells += [_fmt(float(np.mean(wr)), se) if wr else "–", _fmt(float(np.mean(f1))) if f1 else "–"]
        rows.append(f"| {k} | " + " | ".join(cells) + " |")
    return "\n".join(rows)


def coverage(results: Mapping[str, Any]) -> set[tuple[str, str, str]]:
    """``(section, intent, kernel)`` entries of RQ1 and RQ2 a results dictionary holds."""
    out = set()
    for section in ("rq1", "rq2"):
        for intent, per in (results.get(section) or {}).items():
            out.update((section, intent, k) for k in per)
    return out


def save_results(results: dict, out: Path) -> Path:
    """Write ``out/results.json`` atomically as strict JSON (NaN, e.g. the AUC of a one-class subset, is
    ``null``). A results file that holds entries the new one lacks is never lost: it is kept as
    ``results.prev.json`` and a warning names what is missing."""
    path = out / "results.json"
    if path.exists():
        try:
            old = json.loads(path.read_text(encoding="utf-8"))
        except (OSError, ValueError):
            old = None
        missing = sorted(coverage(old) - coverage(results)) if isinstance(old, dict) else []
        if missing:
            keep = out / "results.prev.json"
            path.replace(keep)
            shown = ", ".join("/".join(m) for m in missing[:8]) + (" ..." if len(missing) > 8 else "")
            log.warning("%s held results the new run does not have (%s); the old file is kept as %s",
                        path, shown, keep)
    write_json(path, results)
    return path


def write_report(results: dict, out: Path, command: str = "") -> Path:
    """Write ``out/report.md`` (tables + figures inline) and ``out/results.json`` (:func:`save_results`)."""
    out.mkdir(parents=True, exist_ok=True)
    figures = make_figures(results, out)
    save_results(results, out)
    lines = ["# gift reproduce report", ""]
    if command:
        lines += ["Made by:", "", f"```\n{command}\n```", ""]
    cfg = results.get("config", {})
    if cfg:
        lines += ["Configuration: " + ", ".join(f"`{k}={v}`" for k, v in cfg.items()), ""]
    if results.get("intents"):
        lines += ["## Intents the kernels were conditioned on", "", "| intent | source | text |", "|---|---|---|"]
        lines += [f"| {i} | {d.get('source', '')} | {d.get('text', '')} |" for i, d in results["intents"].items()]
        lines.append("")
    if results.get("relevant"):
        lines += ["## Relevant training objects", "",
                  "Inferred from the demonstrations in inferred mode (the suite's labels are never read there); "
                  "the suite's labels in ground-truth mode.", "", "| intent | source | relevant |", "|---|---|---|"]
        lines += [f"| {i} | {d.get('source', '')} | {', '.join(d.get('names', []))} |"
                  for i, d in results["relevant"].items()]
        lines.append("")
    if results.get("sanity"):
        lines += ["## Sanity check: inferred intents", "",
                  "| intent | LM-inferred (cosine to truth) | generic control |", "|---|---|---|"]
        for i, s in results["sanity"].items():
            lines.append(f"| {i} | {_fmt(*s['inferred'])} | {_fmt(*s['generic'])} |")
        lines.append("")
    if results.get("rq1"):
        lines += ["## RQ1: pairwise win rate of the aligned reward", "", win_rate_table(results), ""]
    for th in _thresholds(results):
        lines += [f"## RQ2: alignment F1 on S_R ∪ S_conf, {th} threshold", "", f1_table(results, th), ""]
    if results.get("rq3"):
        lines += ["## RQ3: Boltzmann choice among candidates (Franka)", ""]
        for intent, per in results["rq3"].items():
            for k, v in per.items():
                best = int(np.argmax(v["mean"]))
                mass = sum(m for m, r in zip(v["mean"], v["relevant"]) if r)
                lines.append(f"- {intent} / {k}: top choice **{v['objects'][best]}**, "
                             f"probability on relevant objects {mass:.2f}")
        lines.append("")
    if results.get("errors"):
        lines += ["## Failures and fallbacks", "",
                  "What failed and was skipped, and LM answers completed by default (an object an answer leaves "
                  "unmapped aligns to *distractor*); first line of each, every detail is in `results.json`:", ""]
        lines += [f"- {str(e).splitlines()[0][:300]}" for e in results["errors"]] + [""]
    if results.get("timing"):
        lines += ["## Time per stage (s), this run", "", "| stage | seconds |", "|---|---|"]
        lines += [f"| {k} | {v:.1f} |" for k, v in results["timing"].items()] + [""]
    runs = (results.get("manifest") or {}).get("runs") or []
    if runs:
        lines += ["## Runs that made these results", "",
                  "| started | seconds | commit | LM | model sha256 |", "|---|---|---|---|---|"]
        for r in runs:
            git = r.get("git") or {}
            commit = (git.get("commit") or "")[:10] + (" (dirty)" if git.get("dirty") else "")
            lm = r.get("lm") or {}
            lines.append(f"| {r.get('started', '')} | {r.get('seconds', '')} | {commit or '–'} | "
                         f"{lm.get('identity', '–')} | {(lm.get('model_sha256') or '–')[:12]} |")
        lines.append("")
    built = kernel_configurations(results)
    if built:
        lines += ["## Kernels as built", "", "Every option each kernel ran with, defaults included:", ""]
        lines += [f"- `{k}`: `{v}`" for k, v in built.items()] + [""]
    lines += ["## Figures", ""] + [f"![{p.stem}]({p.name})" for p in figures] + [""]
    path = out / "report.md"
    path.write_text("\n".join(lines), encoding="utf-8")
    return path


def kernel_configurations(results: Mapping[str, Any]) -> dict[str, str]:
    """``{kernel spec: repr of the kernel as built}`` from a ``gift reproduce`` result (``alignment``) or an
    ``evaluate-alignment`` result (``kernels``); runs older than the record have none."""
    out: dict[str, str] = {}
    for per_kernel in (results.get("alignment") or {}).values():
        for spec, rec in per_kernel.items():
            if isinstance(rec, Mapping) and rec.get("configuration"):
                out.setdefault(spec, rec["configuration"])
    for spec, rec in (results.get("kernels") or {}).items():
        conf = rec.get("configuration") if isinstance(rec, Mapping) else None
        if conf:
            out.setdefault(spec, conf if isinstance(conf, str) else " | ".join(map(str, conf)))
    return out


# ----------------------------------------------------------------------------- text report


def alignment_report(result: Mapping[str, Any], *, per_intent: bool = True, detailed: bool = False) -> str:
    """Markdown tables: per kernel x threshold on the union (P, R, F1, AUC, FP, FN) with F1 and FP/FN per
    subset; then F1 per intent; ``detailed`` adds every metric per subset."""
    thresholds = result["thresholds"]
    subs = [s for s in REPORT_SUBSETS if s != "all"]
    lines = [f"Suite `{result['suite']}`, intent source `{result['intent_source']}`. Union = every test object, "
             f"pooled over intents; AUC = mean over intents.", ""]
    lines += ["| kernel | threshold | P | R | F1 | AUC | FP | FN | " + " | ".join(f"F1 {_subset_label(s)}" for s in subs)
              + " | " + " | ".join(f"FP/FN {_subset_label(s)}" for s in subs) + " |",
              "|---" * (8 + 2 * len(subs)) + "|"]
    for kname, k in result["kernels"].items():
        if not k["overall"]:
            lines.append(f"| {kname} | - | error: {_first_error(k)} |" + " |" * (6 + 2 * len(subs)))
            continue
        for thr in thresholds:
            o = k["overall"].get(thr, {})
            u = o.get("all")
            if u is None:
                continue
            f1s = " | ".join(f"{o[s]['f1']:.2f}" if s in o else "-" for s in subs)
            fpfn = " | ".join(f"{o[s]['fp']}/{o[s]['fn']}" if s in o else "-" for s in subs)
            lines.append(f"| {kname} | {thr} | {u['precision']:.2f} | {u['recall']:.2f} | **{u['f1']:.2f}** | "
                         f"{_f(u['auc_mean_intent'])} | {u['fp']} | {u['fn']} | {f1s} | {fpfn} |")
        q, u = result.get("queries"), (k.get("queries") or {}).get("all")
        if q and u:  # the same threshold after the simulated human's answers (gift.core.queries)
            o = k["queries"]
            label = (f"{q['threshold']} +{q['n']}q {q['policy']}" + (f" abstain {q['abstain']:g} "
                     f"({sum(r['queries']['n_abstained'] for r in k['intents'].values())} flagged)"
                                                                   if q["abstain"] else ""))
            f1s = " | ".join(f"{o[s]['f1']:.2f}" if s in o else "-" for s in subs)
            fpfn = " | ".join(f"{o[s]['fp']}/{o[s]['fn']}" if s in o else "-" for s in subs)
            lines.append(f"| {kname} | {label} | {u['precision']:.2f} | {u['recall']:.2f} | **{u['f1']:.2f}** | "
                         f"{_f(u['auc_mean_intent'])} | {u['fp']} | {u['fn']} | {f1s} | {fpfn} |")
    if detailed:
        lines += ["", "| kernel | threshold | subset | n | precision | recall | F1 | AUC (mean/intent) | FP | FN |",
                  "|---|---|---|---|---|---|---|---|---|---|"]
        for kname, k in result["kernels"].items():
            for thr in thresholds:
                for sub in REPORT_SUBSETS:
                    m = k["overall"].get(thr, {}).get(sub)
                    if m is None:
                        continue
                    lines.append(f"| {kname} | {thr} | {_subset_label(sub)} | {m['n']} | {m['precision']:.2f} | "
                                 f"{m['recall']:.2f} | {m['f1']:.2f} | {_f(m['auc_mean_intent'])} | {m['fp']} | "
                                 f"{m['fn']} |")
    if per_intent:
        lines += ["", "Per intent (all its test objects):", "",
                  "| kernel | intent | " + " | ".join(f"F1 {t}" for t in thresholds) + " | AUC |",
                  "|---|---|" + "---|" * (len(thresholds) + 1)]
        for kname, k in result["kernels"].items():
            for iid, r in k["intents"].items():
                m = r["metrics"]
                f1s = " | ".join(f"{m[t]['all']['f1']:.2f}" for t in thresholds)
                lines.append(f"| {kname} | {iid} | {f1s} | {_f(m[thresholds[0]]['all']['auc'])} |")
    errs = [(k, i, e) for k, d in result["kernels"].items() for i, e in d["errors"].items()]
    if errs:
        lines += ["", "Errors:"]
        lines += [f"- {k} / {i}: {e.splitlines()[0]}" for k, i, e in errs]
    return "\n".join(lines)


def _first_error(k: Mapping[str, Any]) -> str:
    return next(iter(k["errors"].values()), "no result").splitlines()[0].replace("|", "/")


def _subset_label(sub: str) -> str:
    return "union" if sub == "all" else f"S_{sub}"


def _f(x: float) -> str:
    return "n/a" if x is None or (isinstance(x, float) and math.isnan(x)) else f"{x:.2f}"
