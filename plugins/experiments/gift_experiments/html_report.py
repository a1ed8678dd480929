"""``report.html``: one self-contained page of a ``gift demo`` / ``gift reproduce`` run (works offline: every
image is a data URI, every plot inline SVG, the only script inline; nothing is fetched).

Built from ``results.json`` and the output folder alone, so ``gift report OUT`` regenerates it later:

- ``results.json`` (see :mod:`gift_experiments.report`): configuration, manifest, RQ1-RQ3, intents, the
  relevant training objects, errors, and per intent and kernel the alignment of every test object
  (``alignment``; runs made before the study layer: read from their stage cache
  ``stages/<config key>/align-<intent>-<kernel>.json`` when it is there);
- ``lm_calls.jsonl``: the LM calls of the run (:mod:`gift_experiments.lm_calls`);
- ``views/index.json``: the Meshcat pages of :mod:`gift_experiments.views`;
- ``renders/``: object thumbnails (JPEG, three views), made from the simulator's ``render_object`` the first
  time and read from there afterwards (so regenerating needs Drake only for objects not yet drawn);
- the PNG figures of :func:`gift_experiments.report.make_figures`;
- ``query_curves.json``: optional query curves (the format of ``scripts/query_curves.py``,
  :mod:`gift_experiments.query_curves`), copied there by ``gift report OUT --query-curves FILE``.

Sections (``<section id=...>``): ``run``, ``headline``, ``queries`` (only when the run asked the simulated
human questions, ``gift reproduce --queries N``, or the folder has query curves), one ``intent-<id>`` per intent (inferred intent and
its candidates, win rates, every test object with its renders, label and, per kernel, score, cut, decision
and the training object it maps to; the similarity plots), ``views``, ``rq3``, ``sanity``, ``lm-calls``,
``failures``, ``timing``, ``figures``. A section whose data is missing says so; a section that fails to
build shows its error (``class="section-error"``) and the rest of the page is still written.
"""

from __future__ import annotations

import base64
import hashlib
import io
import json
import logging
import math
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from gift.core.data import DISTRACTOR
from gift_experiments.lm_calls import LM_CALLS, LMCall, read_calls
from gift_experiments.report import KERNEL_ORDER, SUBSET_LABEL, kernel_configurations
from gift_experiments.svg_plots import Line, Point, StripRow, bar_chart, esc, lines, scatter, strips
from gift_experiments.views import load_alignments, main_threshold, relevant_training

log = logging.getLogger(__name__)

REPORT = "report.html"
QUERY_CURVES = "query_curves.json"
#: Colours of the query policies in the query curves (those of :func:`gift_experiments.query_curves.figure`).
POLICY_COLOURS = {"uncertainty": "#1f77b4", "disagreement": "#ff7f0e", "error-bound": "#2ca02c",
                  "expected-error": "#9467bd", "random": "#7f7f7f"}
ORACLE = "oracle-labels"
THUMB_PX = 72
#: At most this many LM calls are written into the page (the rest stay in lm_calls.jsonl).
MAX_LM_CALLS = 600


# ----------------------------------------------------------------------------- helpers


def _num(v: Any, digits: int = 3) -> str:
    if v is None or (isinstance(v, float) and not math.isfinite(v)):
        return "–"
    if isinstance(v, (int, float, np.floating)):
        return f"{float(v):.{digits}f}"
    return esc(v)


def _kernels(block: Mapping[str, Mapping[str, Any]]) -> list[str]:
    names = {k for per in block.values() for k in per}
    return [k for k in KERNEL_ORDER if k in names] + sorted(names - set(KERNEL_ORDER) - {ORACLE}) + \
        ([ORACLE] if ORACLE in names else [])


def _finite(values) -> list[float]:
    """The defined numbers of ``values`` (results.json writes an undefined one as null)."""
    return [float(v) for v in values if isinstance(v, (int, float)) and math.isfinite(v)]


def _missing(what: str) -> str:
    return f'<p class="missing">{esc(what)}</p>'


def _table(head: Sequence[str], rows: Sequence[Sequence[str]], cls: str = "") -> str:
    """Cells are HTML already (escape text with :func:`esc`)."""
    h = "".join(f"<th>{c}</th>" for c in head)
    body = "".join("<tr>" + "".join(f"<td>{c}</td>" for c in r) + "</tr>" for r in rows)
    return f'<table class="{cls}"><thead><tr>{h}</tr></thead><tbody>{body}</tbody></table>'


def _data_uri(path: Path, mime: str) -> str:
    return f"data:{mime};base64," + base64.b64encode(path.read_bytes()).decode("ascii")


# ----------------------------------------------------------------------------- object thumbnails


class Thumbnails:
    """Three JPEG views per object as data URIs, cached in ``out/renders/`` (from the simulator's
    ``render_object``; with ``render=False``, or when no simulator can be built, only cached ones)."""

    def __init__(self, out: Path, robot: str = "franka", render: bool = True, simulator=None) -> None:
        self.folder = Path(out) / "renders"
        self.robot = robot
        self.render = render
        self._sim = simulator
        self.failed: str | None = None

    def _simulator(self):
        if self._sim is None:
            import gift

            self._sim = gift.get_simulator(f"drake-{self.robot}")
        return self._sim

    def __call__(self, obj) -> list[str]:
        a = obj.appearance
        key = hashlib.sha256(json.dumps([obj.name, a.shape, list(a.size), list(a.color)]).encode()).hexdigest()[:16]
        paths = [self.folder / f"{key}_{v}.jpg" for v in range(3)]
        if not all(p.is_file() for p in paths):
            if not self.render or self.failed:
                return []
            try:
                images = self._simulator().render_object(obj)
            except Exception as e:  # noqa: BLE001 - no Drake / no EGL: the page is still written, without images
                self.failed = f"{type(e).__name__}: {e}"
                log.warning("object renders unavailable: %s", self.failed)
                return []
            from PIL import Image

            self.folder.mkdir(parents=True, exist_ok=True)
            for img, p in zip(images, paths):
                buf = io.BytesIO()
                Image.fromarray(np.asarray(img, dtype=np.uint8)).resize((THUMB_PX, THUMB_PX), Image.LANCZOS) \
                    .save(buf, "JPEG", quality=82)
                p.write_bytes(buf.getvalue())
        return [_data_uri(p, "image/jpeg") for p in paths]


# ----------------------------------------------------------------------------- sections


class Report:
    """Builds the page from ``results`` and the output folder ``out`` (see the module docstring)."""

    def __init__(self, results: Mapping[str, Any], out: Path, *, command: str = "",
                 lm_record: Path | None = None, render: bool = True, simulator=None,
                 query_curves: Mapping[str, Any] | None = None) -> None:
        self.r = results
        self.out = Path(out)
        self.command = command
        self.lm_record = Path(lm_record) if lm_record else self.out / LM_CALLS
        self.cfg = results.get("config") or {}
        self.threshold = main_threshold(results)
        self.suite = self._load_suite()
        self.thumbs = Thumbnails(self.out, self.cfg.get("robot", "franka"), render=render, simulator=simulator)
        self.views = self._load_views()
        self.curves = query_curves if query_curves is not None else self._load_curves()

    def _load_curves(self) -> Mapping[str, Any] | None:
        path = self.out / QUERY_CURVES
        if not path.is_file():
            return None
        try:
            return json.loads(path.read_text())
        except ValueError as e:
            log.warning("unreadable %s: %s", path, e)
            return None

    def _load_suite(self):
        name = self.cfg.get("suite")
        if not name:
            return None
        try:
            import gift

            return gift.load_suite(name)
        except Exception as e:  # noqa: BLE001 - a suite file that moved: the page shows what results.json has
            log.warning("suite %r not loadable (%s): object labels come from results.json only", name, e)
            return None

    def _load_views(self) -> list[dict[str, Any]]:
        path = self.out / "views" / "index.json"
        if not path.is_file():
            return []
        try:
            return list(json.loads(path.read_text()))
        except ValueError as e:
            log.warning("unreadable %s: %s", path, e)
            return []

    def intents(self) -> list[str]:
        seen: dict[str, None] = {}
        for sec in ("intents", "rq1", "rq2", "alignment", "scatter"):
            seen.update(dict.fromkeys(self.r.get(sec) or {}))
        return list(seen)

    # ------------------------------------------------------------------ run
    def run(self) -> str:
        m = self.r.get("manifest") or {}
        rows = []
        if self.command:
            rows.append(("command", f"<code>{esc(self.command)}</code>"))
        for k in ("suite", "robot", "intent_source", "reward", "pairs", "seeds", "samples"):
            if k in self.cfg:
                rows.append((k, esc(self.cfg[k])))
        if self.cfg.get("kernels"):
            rows.append(("kernels", esc(", ".join(self.cfg["kernels"]))))
        built = kernel_configurations(self.r)
        if built:
            rows.append(("kernels as built", "<br>".join(f"<code>{esc(k)}</code>: <code>{esc(v)}</code>"
                                                        for k, v in built.items())))
        if self.threshold:
            rows.append(("threshold shown", esc(self.threshold)))
        lm = m.get("lm") or {}
        if lm:
            sha = lm.get("model_sha256") or lm.get("sha256")
            rows.append(("LM", esc(lm.get("identity", "")) + (f" (model sha256 <code>{esc(sha[:16])}…</code>)"
                                                            if sha else "")))
        git = m.get("git")
        if isinstance(git, Mapping) and git.get("commit"):
            rows.append(("git commit", f"<code>{esc(git['commit'][:12])}</code>" + (" (with uncommitted changes)"
                                                                                  if git.get("dirty") else "")))
        suite = m.get("suite")
        if isinstance(suite, Mapping) and suite.get("sha256"):
            rows.append(("suite file", f"{esc(suite.get('path') or suite.get('name', ''))} (sha256 "
                                       f"<code>{esc(suite['sha256'][:16])}…</code>)"))
        for k in ("code_version", "config_key", "python", "platform"):
            if m.get(k) and not isinstance(m[k], (Mapping, list)):
                rows.append((k, f"<code>{esc(m[k])}</code>"))
        if len(m.get("runs") or []) > 1:
            rows.append(("runs", f"{len(m['runs'])} (a first run and its resumes)"))
        total = (self.r.get("timing") or {}).get("total")
        if total is not None:
            rows.append(("time", f"{total:.0f} s"))
        table = "".join(f"<tr><th>{esc(k)}</th><td>{v}</td></tr>" for k, v in rows)
        raw = json.dumps({"config": self.cfg, "manifest": m}, indent=2, default=str)
        return (f'<table class="kv">{table}</table><details><summary>full configuration and manifest</summary>'
                f"<pre>{esc(raw)}</pre></details>")

    # ------------------------------------------------------------------ headline
    def headline(self) -> str:
        rq1, rq2 = self.r.get("rq1") or {}, self.r.get("rq2") or {}
        if not rq1 and not rq2:
            return _missing("No win rates or alignment scores in this results.json.")
        kernels = _kernels({**{i: {**rq2.get(i, {}), **rq1.get(i, {})} for i in set(rq1) | set(rq2)}})
        ths = []
        for per in rq2.values():
            for by_th in per.values():
                ths += [t for t in by_th if t not in ths]
        head = ["kernel", "win rate (mean over intents ± s.e.)"] + [f"F1, {esc(t)} threshold" for t in ths]
        rows = []
        for k in kernels:
            wr = _finite(per[k].get("mean") for per in rq1.values() if k in per)
            se = float(np.std(wr, ddof=1) / np.sqrt(len(wr))) if len(wr) > 1 else None
            cells = [f'<span class="swatch" style="background:{_colour(k)}"></span>{esc(k)}',
                     (_num(float(np.mean(wr))) + (f" ± {se:.3f}" if se is not None else "")) if wr else "–"]
            for t in ths:
                f1 = _finite(per[k][t]["all"].get("f1") for per in rq2.values()
                             if "all" in (per.get(k) or {}).get(t, {}))
                cells.append(_num(float(np.mean(f1))) if f1 else "–")
            rows.append(cells)
        note = (f"<p>{len(rq1) or len(rq2)} intent(s). Win rate: RQ1 pairwise win rate of the aligned reward on test "
                f"scenes of unseen objects (0.5 = chance); F1: RQ2 alignment F1 on {esc(SUBSET_LABEL['all'])}. "
                f"<code>{ORACLE}</code> aligns with the suite's labels (an upper bound).</p>")
        plot = ""
        if rq1:
            intents = list(rq1)
            ks = _kernels(rq1)
            mean = np.array([[rq1[i].get(k, {}).get("mean", np.nan) for i in intents] for k in ks])
            se = np.array([[rq1[i].get(k, {}).get("se", np.nan) for i in intents] for k in ks])
            tips = [[f"{i} / {k}: win rate {_num(rq1[i].get(k, {}).get('mean'))} ± {_num(rq1[i].get(k, {}).get('se'))}"
                     f" (per seed: {', '.join(_num(x) for x in rq1[i].get(k, {}).get('per_seed', []))})"
                     for i in intents] for k in ks]
            plot = bar_chart(intents, ks, mean, se, tips=tips, ylabel="pairwise win rate", ref=0.5,
                             title="RQ1: win rate of the aligned reward per intent (± s.e. over seeds)",
                             kind="win-rate")
        return _table(head, rows, "headline") + note + plot

    # ------------------------------------------------------------------ one intent
    def intent(self, intent: str) -> str:
        al = load_alignments(self.r, self.out, intent)  # read once: four sections use it
        parts = [self._intent_text(intent), self._kernel_categories(al), self._intent_scores(intent, al),
                 self._objects(intent, al), self._similarity(intent, al)]
        views = [v for v in self.views if v.get("intent") == intent and v.get("file")]
        if views:
            parts.append("<p>Replays in Meshcat: " + ", ".join(
                f'<a href="{esc(v["file"])}">{esc(v.get("title") or v["file"])}</a>' for v in views) + "</p>")
        return "".join(parts)

    def _spec(self, intent: str):
        if self.suite is None:
            return None
        try:
            return self.suite.intent(intent)
        except Exception:  # noqa: BLE001
            return None

    def _intent_text(self, intent: str) -> str:
        d = (self.r.get("intents") or {}).get(intent)
        spec = self._spec(intent)
        out = []
        if spec is not None:
            out.append(f'<p class="task">Task <code>{esc(spec.task)}</code>; training objects: '
                       f"{esc(', '.join(spec.train_objects))} (the suite's human cares about "
                       f"{esc(', '.join(spec.relevant_train) or 'none')}).</p>")
        rel = (self.r.get("relevant") or {}).get(intent)
        if isinstance(rel, Mapping) and rel.get("names") is not None:
            src = {"demonstrations": "inferred from the demonstrations", "suite": "the suite's labels"}.get(
                rel.get("source"), esc(rel.get("source", "")))
            out.append(f'<p class="relevant">Relevant training objects the run used ({src}): '
                       f"<b>{esc(', '.join(rel['names']) or 'none')}</b></p>")
        if not d:
            out.append(_missing("No intent recorded for this intent in results.json."))
        else:
            src = d.get("source", "")
            out.append(f'<p class="intent-text"><b>{"Inferred" if src == "inferred" else "Intent"} intent</b> '
                       f"({esc(src)}): <q>{esc(d.get('text', ''))}</q></p>")
            if spec is not None and src != "ground-truth":
                out.append(f'<p class="truth">The suite\'s ground truth: <q>{esc(spec.text)}</q></p>')
            cands = d.get("candidates")
            if cands:
                items = []
                for c in cands:
                    if isinstance(c, Mapping):
                        text = c.get("text") or c.get("intent") or c.get("name") or ""
                        extra = ", ".join(f"{esc(k)} {_num(v) if isinstance(v, (int, float)) else esc(v)}"
                                          for k, v in c.items() if k not in ("text", "intent", "name")
                                          and not isinstance(v, (list, dict)))
                        items.append(f"<li>{esc(text)}{f' <small>({extra})</small>' if extra else ''}</li>")
                    else:
                        items.append(f"<li>{esc(c)}</li>")
                out.append(f'<div class="candidates"><b>Candidates</b><ol>{"".join(items)}</ol></div>')
            mots = d.get("motivations") or []
            axes = d.get("axes") or []
            if mots or axes:
                det = ""
                if mots:
                    det += "<b>Motivations</b><ul>" + "".join(
                        f"<li>{esc(m.get('text', m) if isinstance(m, Mapping) else m)}"
                        + (f" <small>(features: {esc(', '.join(map(str, m.get('features') or [])))})</small>"
                           if isinstance(m, Mapping) and m.get("features") else "") + "</li>" for m in mots) + "</ul>"
                if axes:
                    det += "<b>Semantic axes</b><ul>" + "".join(
                        f"<li>{esc(a.get('question', a) if isinstance(a, Mapping) else a)}"
                        + (f" <small>({esc(', '.join(map(str, a.get('objects') or [])))})</small>"
                           if isinstance(a, Mapping) and a.get("objects") else "") + "</li>" for a in axes) + "</ul>"
                out.append(f"<details><summary>motivations and axes the LM gave</summary>{det}</details>")
        return "".join(out)

    @staticmethod
    def _kernel_categories(al: Mapping[str, Any]) -> str:
        """What a category-asking kernel (``gift-prob``) asked about: the goal's category, the ladder's
        rungs named from the demonstrated objects, and its terms' weights (from its ``details``)."""
        rows = []
        for kernel, by_th in al.items():
            det = next((b.get("details") for b in by_th.values() if isinstance(b, Mapping) and b.get("details")), None)
            if not isinstance(det, Mapping) or not (det.get("category") or det.get("ladder")):
                continue
            text = f"<b>{esc(kernel)}</b> asked whether each object is one of the <q>{esc(det.get('category', ''))}</q>"
            ladder = det.get("ladder")
            if isinstance(ladder, Mapping) and ladder.get("categories"):
                n = len(ladder["categories"])
                rungs = " &rarr; ".join(f"<q>{esc(c)}</q>" for c in ladder["categories"])
                text += (f", and of {n} categor{'y' if n == 1 else 'ies'} named from the demonstrated objects "
                         f"alone, narrow to broad: {rungs} (its LM term averages all {n + 1})")
            weights = det.get("weights")
            if isinstance(weights, Mapping) and weights:
                text += " <small>(term weights: " + ", ".join(
                    f"{esc(k)} {_num(v, 2)}" for k, v in weights.items() if isinstance(v, (int, float))) + ")</small>"
            rows.append(f'<p class="kernel-category">{text}.</p>')
        return "".join(rows)

    def _intent_scores(self, intent: str, al: Mapping[str, Any]) -> str:
        rq1 = (self.r.get("rq1") or {}).get(intent) or {}
        rq2 = (self.r.get("rq2") or {}).get(intent) or {}
        kernels = _kernels({"x": {**rq2, **rq1}})
        if not kernels:
            return _missing("No scores for this intent.")
        rows = []
        for k in kernels:
            w = rq1.get(k) or {}
            m = (rq2.get(k) or {}).get(self.threshold, {}).get("all") if self.threshold else None
            block = (al.get(k) or {}).get(self.threshold) if self.threshold else None
            cut = _num(block.get("cut")) if block else "–"
            note = esc(block.get("note", "")) if block else ""
            rows.append([f'<span class="swatch" style="background:{_colour(k)}"></span>{esc(k)}',
                         (_num(w.get("mean")) + (f" ± {_num(w.get('se'))}" if "se" in w else "")) if w else "–",
                         _num(m.get("f1")) if m else "–", _num(m.get("auc")) if m else "–",
                         (f"{m.get('fp', '–')} / {m.get('fn', '–')}" if m else "–"),
                         f"{cut} <small>{note}</small>"])
        return _table(["kernel", "win rate ± s.e.", f"F1 ({esc(self.threshold or '–')})", "AUC", "FP / FN",
                       "cut (how chosen)"], rows, "scores")

    def _object_list(self, intent: str, al: Mapping[str, Any]) -> list[tuple[str, bool | None, tuple[str, ...]]]:
        """``[(object, relevant or None, confounds)]`` in the suite's order (else from the results)."""
        spec = self._spec(intent)
        if spec is not None:
            return [(t.object, bool(t.relevant), tuple(t.confounds)) for t in spec.test]
        names: dict[str, bool | None] = {}
        for p in ((self.r.get("scatter") or {}).get(intent) or {}).get("points") or []:
            names[p["object"]] = bool(p.get("relevant"))
        for by_th in al.values():
            for block in by_th.values():
                for n in block.get("mapping") or {}:
                    names.setdefault(n, None)
        return [(n, rel, ()) for n, rel in names.items()]

    def _objects(self, intent: str, al: Mapping[str, Any]) -> str:
        objects = self._object_list(intent, al)
        if not objects:
            return _missing("No test objects recorded for this intent.")
        kernels = _kernels({"x": al})
        spec = self._spec(intent)
        rel_names = relevant_training(self.r, intent, spec)
        relevant_train = set(rel_names) if rel_names is not None else None
        head = ["#", "object", "renders", "label"]
        for k in kernels:
            block = (al[k].get(self.threshold) or next(iter(al[k].values()), {})) if al[k] else {}
            head.append(f'{esc(k)}<br><small>cut {_num(block.get("cut"))}</small>')
        rows = []
        specs = {o.name: o for o in self.suite.specs([n for n, _, _ in objects])} if spec is not None else {}
        for i, (name, rel, conf) in enumerate(objects, 1):
            imgs = self.thumbs(specs[name]) if name in specs else []
            pics = "".join(f'<img src="{u}" alt="{esc(name)}, view {v + 1}" width="{THUMB_PX}" height="{THUMB_PX}">'
                           for v, u in enumerate(imgs)) or '<span class="missing">no render</span>'
            label = ('<span class="rel">relevant</span>' if rel else '<span class="irr">not relevant</span>'
                     if rel is not None else "–")
            if conf:
                label += "<br><small>confounds: " + esc(", ".join(SUBSET_LABEL.get(c, c) for c in conf)) + "</small>"
            cells = [str(i), f"<b>{esc(name)}</b>", f'<div class="renders">{pics}</div>', label]
            for k in kernels:
                cells.append(self._decision_cell(al[k], name, rel, relevant_train))
            rows.append(f'<tr class="object-row" data-object="{esc(name)}" data-intent="{esc(intent)}">'
                        + "".join(f"<td>{c}</td>" for c in cells) + "</tr>")
        h = "".join(f"<th>{c}</th>" for c in head)
        legend = ("<p><small>Per kernel: the decision score (compared with the cut), the decision and the training "
                  "object the test object maps to; green cells agree with the label, red ones do not. "
                  f"Threshold: {esc(self.threshold or '–')}.</small></p>")
        return (f'<h3>Test objects ({len(objects)})</h3>{legend}<table class="objects" data-intent="{esc(intent)}">'
                f"<thead><tr>{h}</tr></thead><tbody>{''.join(rows)}</tbody></table>")

    def _decision_cell(self, by_th: Mapping[str, Any], name: str, rel: bool | None,
                       relevant_train: set[str] | None) -> str:
        block = by_th.get(self.threshold) or next(iter(by_th.values()), None) if by_th else None
        if not block or name not in (block.get("mapping") or {}):
            return "–"
        target = block["mapping"][name]
        obj = (block.get("objects") or {}).get(name) or {}
        score = obj.get("decision")
        kind = "decision"
        if score is None:
            score, kind = (block.get("scores") or {}).get(name), "K at the match"
        aligned = target != DISTRACTOR
        if block.get("relevant_train") is not None:  # what the kernel was told (the study records it)
            relevant_train = set(block["relevant_train"])
        predicted = aligned and (relevant_train is None or target in relevant_train)
        ok = None if rel is None else predicted == rel
        cls = "" if ok is None else (' class="ok"' if ok else ' class="bad"')
        what = f"→ {esc(target)}" if aligned else "distractor"
        closest = obj.get("match")
        extra = f'<br><small>closest: {esc(closest)}</small>' if not aligned and closest else ""
        return (f'<div{cls} title="{esc(kind)} {_num(score)}, cut {_num(block.get("cut"))}">'
                f"<span class=\"score\">{_num(score)}</span> {what}{extra}</div>")

    def _similarity(self, intent: str, al: Mapping[str, Any]) -> str:
        out = []
        objects = {n: rel for n, rel, _ in self._object_list(intent, al)}
        rows = []
        for k in _kernels({"x": al}):
            block = al[k].get(self.threshold) or next(iter(al[k].values()), None)
            if not block:
                continue
            objs = block.get("objects") or {}
            values = {n: (objs.get(n) or {}).get("decision") for n in block.get("mapping", {})}
            if any(v is None for v in values.values()):
                values = {n: (block.get("scores") or {}).get(n) for n in block.get("mapping", {})}
            pts = []
            for n, v in values.items():
                if v is None:
                    continue
                t = block["mapping"][n]
                tip = (f"{n}: {k} score {v:.3f} {'≥' if t != DISTRACTOR else '<'} cut {_num(block.get('cut'))} → "
                       f"{t if t != DISTRACTOR else 'distractor'} ({'relevant' if objects.get(n) else 'not relevant'})")
                pts.append(Point(float(v), 0.0, n, bool(objects.get(n)), tip))
            rows.append(StripRow(k, block.get("cut"), tuple(pts)))
        if rows:
            out.append(strips(rows, title="Decision score per test object and kernel (line: the cut; green: "
                                          "relevant)"))
        sc = (self.r.get("scatter") or {}).get(intent) or {}
        if sc.get("points"):
            pts = [Point(p["language"], p["vision"], p["object"], bool(p.get("relevant")),
                         f"{p['object']}: language {p['language']:.3f}, vision {p['vision']:.3f} "
                         f"({'relevant' if p.get('relevant') else 'not relevant'})") for p in sc["points"]]
            out.append(scatter(pts, xlabel="language similarity to anchor", ylabel="vision similarity to anchor",
                               title=f"Surface similarity to the anchor {sc.get('anchor', '')}",
                               anchor=(1.0, 1.0, sc.get("anchor", "")), kind="similarity"))
        if not out:
            return _missing("No similarity data for this intent.")
        return '<h3>Similarity plots</h3><div class="plots">' + "".join(out) + "</div>"

    # ------------------------------------------------------------------ questions asked
    def query_rows(self) -> list[tuple[str, str, str, Mapping[str, Any], Mapping[str, Any]]]:
        """``[(intent, kernel, row, alignment record, queries record)]``: each kernel the run asked the simulated
        human about (``alignment[intent][kernel]["queries"]``, :func:`gift.study.chain.query_stage`); ``row``:
        its row in RQ1/RQ2 (:func:`gift.study.chain.query_label`)."""
        out = []
        for intent, per in (self.r.get("alignment") or {}).items():
            for kernel, rec in (per.items() if isinstance(per, Mapping) else ()):
                q = rec.get("queries") if isinstance(rec, Mapping) else None
                if isinstance(q, Mapping):
                    out.append((intent, kernel, self._query_row(intent, kernel, q), rec, q))
        return out

    def _query_row(self, intent: str, kernel: str, q: Mapping[str, Any]) -> str:
        from types import SimpleNamespace

        from gift.study.chain import query_label

        label = query_label(kernel, SimpleNamespace(queries=q.get("queries") or 0, query_policy=q.get("policy", ""),
                                                    abstain=q.get("abstain") or 0.0))
        rows = {**((self.r.get("rq2") or {}).get(intent) or {}), **((self.r.get("rq1") or {}).get(intent) or {})}
        if label not in rows:  # a label format of another version: the row that extends the kernel's name
            label = next((k for k in rows if k.startswith(kernel + " ") and k not in self.cfg.get("kernels", [])),
                         label)
        return label

    def _before_after(self, intent: str, kernel: str, row: str, q: Mapping[str, Any]) -> dict[str, Any]:
        """F1 (at the threshold the answers moved) and RQ1 win rate of ``kernel`` before and of ``row`` after."""
        th = q.get("threshold")
        rq1 = (self.r.get("rq1") or {}).get(intent) or {}
        rq2 = (self.r.get("rq2") or {}).get(intent) or {}

        def f1(block):
            return (((block or {}).get(th) or {}).get("all") or {}).get("f1")

        after = f1(rq2.get(row)) if row in rq2 else f1(q.get("metrics"))
        return {"f1": (f1(rq2.get(kernel)), after),
                "win": ((rq1.get(kernel) or {}).get("mean"), (rq1.get(row) or {}).get("mean")),
                "se": ((rq1.get(kernel) or {}).get("se"), (rq1.get(row) or {}).get("se"))}

    @staticmethod
    def _answers_text(q: Mapping[str, Any]) -> str:
        return ", ".join(f"{a['object']} ({_answer_word(a)})" for a in q.get("answers") or []) or "none"

    def queries(self) -> str:
        rows = self.query_rows()
        parts = []
        if rows:
            parts += [self._query_summary(rows), self._query_plots(rows), self._query_answers(rows)]
        if self.curves:
            parts.append(self._query_curves())
        return "".join(parts)

    def _query_summary(self, rows) -> str:
        by_row: dict[str, list] = {}
        for intent, kernel, row, _, q in rows:
            by_row.setdefault(row, []).append((intent, kernel, q))
        out = []
        for row, items in by_row.items():
            kernel, q0 = items[0][1], items[0][2]
            ba = [self._before_after(i, k, row, q) for i, k, q in items]

            def mean(key, j):
                v = _finite(b[key][j] for b in ba)
                return float(np.mean(v)) if v else None

            asked = [int(q.get("asked", len(q.get("answers") or []))) for _, _, q in items]
            flagged = sum(int(q.get("n_abstained") or 0) for _, _, q in items)
            out.append([f'<span class="swatch" style="background:{_colour(kernel)}"></span>{esc(kernel)}',
                        f"<code>{esc(row)}</code>", esc(q0.get("policy", "–")),
                        f"{q0.get('queries', '–')} (asked {_num(float(np.mean(asked)), 1)} on average)",
                        esc(q0.get("threshold", "–")),
                        f"{_num(mean('f1', 0))} → <b>{_num(mean('f1', 1))}</b>",
                        f"{_num(mean('win', 0))} → <b>{_num(mean('win', 1))}</b>",
                        f"{flagged} (band {_num(q0.get('abstain') or 0.0, 2)})" if q0.get("abstain") else "–"])
        note = (f"<p>{len({r[0] for r in rows})} intent(s). The simulated human (the suite's labels) answered up to "
                "the given number of questions per intent and kernel, chosen by the policy; the answers re-score the "
                "kernel's alignment (no kernel runs again) and move the cut of the threshold shown. Before → after: "
                "mean over intents of the F1 on every test object and of the RQ1 win rate.</p>")
        return note + _table(["kernel", "row after the answers", "policy", "questions per intent", "threshold",
                              "F1 before → after", "win rate before → after", "abstained"], out, "queries")

    def _query_plots(self, rows) -> str:
        intents = list(dict.fromkeys(r[0] for r in rows))
        pairs = list(dict.fromkeys((r[1], r[2]) for r in rows))  # (kernel, row)
        series = [name for pair in pairs for name in pair]
        cell = {(i, row): (k, q) for i, k, row, _, q in rows}
        plots = []
        for key, what, ylabel, ref in (("f1", "F1", "alignment F1", None), ("win", "win rate", "pairwise win rate",
                                                                              0.5)):
            mean = np.full((len(series), len(intents)), np.nan)
            se = np.full_like(mean, np.nan)
            tips = [[""] * len(intents) for _ in series]
            for g, intent in enumerate(intents):
                for p, (kernel, row) in enumerate(pairs):
                    if (intent, row) not in cell:
                        continue
                    q = cell[(intent, row)][1]
                    ba = self._before_after(intent, kernel, row, q)
                    for j, when in enumerate(("before the questions", f"after {q.get('asked', 0)} question(s): "
                                                                      f"{self._answers_text(q)}")):
                        s = 2 * p + j
                        v, e = ba[key][j], ba["se"][j] if key == "win" else None
                        mean[s, g] = v if v is not None else np.nan
                        se[s, g] = e if e is not None else np.nan
                        tips[s][g] = (f"{intent} / {series[s]}: {what} {_num(v)}" + (f" ± {_num(e)}" if e is not None
                                                                                      else "") +
                                      (f" ({q.get('threshold')} threshold)" if key == "f1" else "") + f", {when}")
            if np.isfinite(mean).any():
                plots.append(bar_chart(intents, series, mean, se, tips=tips, ylabel=ylabel, ref=ref,
                                       title=f"{what} per intent before and after the questions",
                                       kind=f"queries-{key}"))
        return '<div class="plots">' + "".join(plots) + "</div>" if plots else ""

    def _query_answers(self, rows) -> str:
        out = []
        for intent, kernel, row, rec, q in rows:
            th = q.get("threshold")
            before = (((rec.get("thresholds") or {}).get(th)) or {}).get("mapping") or {}
            after = q.get("mapping") or {}
            items = []
            for a in q.get("answers") or []:
                o = a["object"]
                was, now = before.get(o), after.get(o)
                moved = (f" <small>({'→ ' + esc(was) if was not in (None, DISTRACTOR) else 'distractor'} before, "
                         f"{'→ ' + esc(now) if now not in (None, DISTRACTOR) else 'distractor'} after)</small>"
                         if was is not None or now is not None else "")
                items.append(f'<li data-object="{esc(o)}"><b>{esc(o)}</b>: {esc(_answer_word(a))}{moved}</li>')
            asked = f"<ol>{''.join(items)}</ol>" if items else '<span class="missing">no question asked</span>'
            if q.get("rescored_ladder"):
                asked += (f'<small class="rescored">re-scored with the answers; ladder named again: '
                          f'{esc(" > ".join(q["rescored_ladder"]))}</small>')
            elif q.get("rescored"):
                asked += '<small class="rescored">re-scored with the answers</small>'
            ab = q.get("abstained") or []
            ba = self._before_after(intent, kernel, row, q)
            out.append(f'<tr class="query-row" data-intent="{esc(intent)}" data-kernel="{esc(kernel)}">'
                       + "".join(f"<td>{c}</td>" for c in [
                           esc(intent), f"<code>{esc(row)}</code>", asked,
                           f"{_num(q.get('cut'))} <small>{esc(q.get('note', ''))}</small>",
                           esc(", ".join(ab)) if ab else "–", _num(q.get("error_bound")),
                           f"{_num(ba['f1'][0])} → <b>{_num(ba['f1'][1])}</b>",
                           f"{_num(ba['win'][0])} → <b>{_num(ba['win'][1])}</b>"]) + "</tr>")
        head = "".join(f"<th>{c}</th>" for c in ["intent", "row", "questions (in the order asked) and answers",
                                                  "cut after (how placed)", "abstained", "error bound", "F1",
                                                  "win rate"])
        return (f'<h3>Questions and answers per intent</h3><table class="query-answers"><thead><tr>{head}</tr>'
                f"</thead><tbody>{''.join(out)}</tbody></table>")

    def _query_curves(self) -> str:
        runs = self.curves.get("runs") if "runs" in self.curves else {"": self.curves}
        out = []
        for name, sim in (runs or {}).items():
            grid, curves = sim.get("grid") or [], sim.get("curves") or {}
            if not grid or not curves:
                continue
            for key, what in (("f1", "alignment F1 (pooled)"), ("win", "win rate (mean over intents)")):
                ls = []
                for policy, c in curves.items():
                    ys = tuple(c.get(key) or ())
                    if not any(v is not None for v in ys):
                        continue
                    band = tuple(c[key + "_se"]) if c.get(key + "_se") else None
                    tips = tuple(f"{name + ': ' if name else ''}{policy}, {k} question(s) per intent: {what} "
                                 f"{_num(v)}" + (f" ± {_num(band[j])} (s.e. over seeds)" if band else "")
                                 for j, (k, v) in enumerate(zip(grid, ys)))
                    ls.append(Line(policy, ys, band, tips, dashed=policy == "random",
                                   colour=POLICY_COLOURS.get(policy, "")))
                if ls:
                    out.append(lines(grid, ls, xlabel="questions per intent", ylabel=what.split(" (")[0],
                                     title=f"{name}: {what}" if name else what, kind=f"query-curve-{key}"))
        if not out:
            return _missing("The query curves file has no curves.")
        cmd = self.curves.get("command")
        src = f" (<code>{esc(cmd)}</code>)" if cmd else ""
        return (f"<h3>Query curves</h3><p>From <code>{QUERY_CURVES}</code>{src}: each policy asks k questions "
                "per intent, answered from the suite's labels; random is the mean over seeds, shaded ± s.e.</p>"
                f'<div class="plots">{"".join(out)}</div>')

    # ------------------------------------------------------------------ views, rq3, sanity
    def views_section(self) -> str:
        if not self.views:
            return _missing("No Meshcat replays in this folder (gift view OUT --export FILE.html writes one).")
        rows = []
        for v in self.views:
            if v.get("file"):
                link = f'<a href="{esc(v["file"])}">{esc(v.get("title") or v["file"])}</a>'
                clips = "<ul>" + "".join(f"<li>{esc(c)}</li>" for c in v.get("clips") or []) + "</ul>"
            else:
                link = esc(f"{v.get('intent')} / {v.get('view')}")
                clips = f'<span class="bad">{esc(v.get("error"))}</span>'
            rows.append([link, clips])
        return ("<p>Self-contained pages (Drake's Meshcat; they open with no server and no network) next to this "
                "report:</p>" + _table(["replay", "clips"], rows, "views"))

    def rq3(self) -> str:
        rq3 = self.r.get("rq3") or {}
        if not rq3:
            return _missing("RQ3 did not run.")
        out = []
        for intent, per in rq3.items():
            ks = [k for k in _kernels({"x": per})]
            objs = per[ks[0]]["objects"]
            rel = per[ks[0]]["relevant"]
            mean = np.array([per[k]["mean"] for k in ks])
            se = np.array([per[k]["se"] for k in ks])
            labels = [f"{o}{' *' if r else ''}" for o, r in zip(objs, rel)]
            tips = [[f"{k}: P({objs[j]}) = {mean[i, j]:.3f} ± {se[i, j]:.3f} "
                     f"({'relevant' if rel[j] else 'not relevant'})" for j in range(len(objs))]
                    for i, k in enumerate(ks)]
            out.append(bar_chart(labels, ks, mean, se, tips=tips, ylabel="Boltzmann probability",
                                 title=f"{intent}: choice among candidates (* = relevant)", kind="rq3"))
        return '<div class="plots">' + "".join(out) + "</div>"

    def sanity(self) -> str:
        s = self.r.get("sanity") or {}
        if not s:
            return _missing("The intent sanity check did not run (sanity_reps = 0).")
        rows = []
        for i, v in s.items():
            texts = "".join(f"<li>{esc(t)}</li>" for t in v.get("texts") or [])
            rows.append([esc(i), f"{_num(v['inferred'][0])} ± {_num(v['inferred'][1])}", _num(v["generic"][0]),
                         f"<details><summary>{len(v.get('texts') or [])} texts</summary><ul>{texts}</ul></details>"])
        return _table(["intent", "inferred (MiniLM cosine to the truth)", "generic control", "inferred texts"], rows)

    # ------------------------------------------------------------------ LM calls
    def lm_calls(self) -> str:
        usage = ((self.r.get("manifest") or {}).get("lm") or {}).get("usage") or {}
        head = ""
        if usage:
            def shown(v: Any) -> str:
                if isinstance(v, Mapping):  # answers per build of the model runtime (made_by)
                    return "(" + "; ".join(f"{esc(b)}: {esc(n)}" for b, n in v.items()) + ")" if v else "(none)"
                return _num(v, 1) if isinstance(v, float) else esc(v)

            head = "<p>LM usage of the run: " + ", ".join(f"{esc(k)} {shown(v)}" for k, v in usage.items()) + ".</p>"
        if not self.lm_record.is_file():
            return head + _missing(f"No LM call record ({self.lm_record.name}) in this folder: the run made no LM "
                                   "call, or was not run by gift demo / gift reproduce.")
        calls = read_calls(self.lm_record)
        if not calls:
            why = ("its answers came from the stage cache of an earlier run" if usage else
                   "no stage of it needed an LM, or its answers came from the stage cache of an earlier run")
            return head + f"<p>This invocation made no LM call: {why}.</p>"
        hits = sum(c.cached is True for c in calls)
        misses = sum(c.cached is False for c in calls)
        tok = sum((c.prompt_tokens or 0) + (c.completion_tokens or 0) for c in calls)
        summary = (f"<p>{len(calls)} calls recorded in <code>{esc(self.lm_record.name)}</code>: {hits} cache hits, "
                   f"{misses} misses, {tok} tokens (as counted when first answered). Replay them with "
                   f"<code>--lm replay:{esc(self.lm_record.name)}</code>.</p>")
        shown = calls[:MAX_LM_CALLS]
        more = (f"<p>Only the first {MAX_LM_CALLS} are shown; every call is in the record file.</p>"
                if len(calls) > MAX_LM_CALLS else "")
        return head + summary + more + '<div class="lm-calls">' + "".join(_lm_call(c) for c in shown) + "</div>"

    # ------------------------------------------------------------------ failures
    def failures(self) -> str:
        errs = list(self.r.get("errors") or [])
        view_errs = [f"view {v.get('intent')}/{v.get('view')}: {v['error']}" for v in self.views if v.get("error")]
        if self.thumbs.failed:
            view_errs.append(f"object renders: {self.thumbs.failed}")
        if not errs and not view_errs:
            return "<p>No failures or fallbacks were recorded.</p>"
        items = "".join(f'<li class="failure"><pre>{esc(e)}</pre></li>' for e in errs + view_errs)
        return ("<p>What failed and was skipped, and LM answers completed by default (an object an answer leaves "
                f"unmapped aligns to <i>distractor</i>):</p><ul>{items}</ul>")

    def timing(self) -> str:
        t = self.r.get("timing") or {}
        if not t:
            return _missing("No timing recorded.")
        return _table(["stage", "seconds"], [[esc(k), _num(v, 1)] for k, v in t.items()], "timing")

    def figures(self) -> str:
        pngs = sorted(self.out.glob("*.png"))
        if not pngs:
            return _missing("No PNG figures in this folder.")
        imgs = "".join(f'<figure><img src="{_data_uri(p, "image/png")}" alt="{esc(p.stem)}">'
                       f"<figcaption>{esc(p.name)}</figcaption></figure>" for p in pngs)
        return f"<details><summary>{len(pngs)} figures (the PNG files of report.md)</summary>{imgs}</details>"

    # ------------------------------------------------------------------ page
    def html(self) -> str:
        sections: list[tuple[str, str, Callable[[], str]]] = [
            ("run", "Run", self.run), ("headline", "Headline", self.headline)]
        if self.query_rows() or self.curves:
            sections.append(("queries", "Questions asked", self.queries))
        for i in self.intents():
            sections.append((f"intent-{i}", f"Intent {i}", lambda i=i: self.intent(i)))
        sections += [("views", "Replays (Meshcat)", self.views_section),
                     ("rq3", "RQ3: choice among candidates", self.rq3),
                     ("sanity", "Sanity check of the inferred intents", self.sanity),
                     ("lm-calls", "LM calls", self.lm_calls), ("failures", "Failures and fallbacks", self.failures),
                     ("timing", "Time per stage", self.timing), ("figures", "Static figures", self.figures)]
        body = []
        for sid, title, build in sections:
            try:
                content = build()
            except Exception as e:  # noqa: BLE001 - one broken section must not lose the page
                log.exception("report.html: section %s failed", sid)
                content = (f'<p class="section-error">This section could not be built: {esc(type(e).__name__)}: '
                           f"{esc(e)}</p>")
            body.append(f'<section id="{esc(sid)}"><h2>{esc(title)}</h2>{content}</section>')
        nav = " · ".join(f'<a href="#{esc(s)}">{esc(t)}</a>' for s, t, _ in sections)
        intents = ", ".join(self.intents())
        return (f"<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><meta name=\"viewport\" "
                f"content=\"width=device-width, initial-scale=1\"><title>gift report: {esc(intents)}</title>"
                f"<style>{CSS}</style></head><body><header><h1>gift report</h1><p>{esc(intents)} · "
                f"{esc(self.cfg.get('robot', ''))}</p><nav>{nav}</nav></header><main>{''.join(body)}</main>"
                f'<div id="tip" role="tooltip"></div><script>{SCRIPT}</script></body></html>\n')


def _colour(kernel: str) -> str:
    from gift_experiments.svg_plots import colour

    return colour(kernel)


def _answer_word(a: Mapping[str, Any]) -> str:
    """An answer of the simulated human in words: relevant, not relevant or don't know, and what it plays."""
    word = {True: "yes, relevant", False: "no, not relevant"}.get(a.get("relevant"), "don't know")
    return word + (f", plays {a['plays']}" if a.get("plays") else "")


def _lm_call(c: LMCall) -> str:
    tokens = (f"{c.prompt_tokens}+{c.completion_tokens} tokens" if c.prompt_tokens is not None else "choice")
    hit = {True: '<span class="hit">cache hit</span>', False: '<span class="miss">miss</span>'}.get(c.cached, "?")
    secs = f"{c.seconds:.2f} s" if c.seconds is not None else ""
    preview = c.answer.replace("\n", " ")[:90]
    msgs = "".join(f'<div class="msg"><b>{esc(m["role"])}</b><pre>{esc(m["content"])}</pre></div>' for m in c.messages)
    params = ", ".join(f"{k}={v}" for k, v in c.parameters.items() if k != "json_schema")
    return (f'<details class="lm-call" data-cached="{str(c.cached).lower()}"><summary>#{c.index} {esc(c.kind)} · '
            f"{tokens} · {hit} · {secs} · <q>{esc(preview)}</q></summary>"
            f"<p><small>{esc(c.identity)}; {esc(params)}</small></p>{msgs}"
            f'<div class="msg answer"><b>answer</b><pre>{esc(c.answer)}</pre></div></details>')


CSS = """
body { font: 14px/1.45 system-ui, -apple-system, "Segoe UI", sans-serif; margin: 0; color: #222; background: #fafafa; }
header { background: #23395d; color: #fff; padding: 10px 22px; }
header h1 { margin: 0; font-size: 22px; } header p { margin: 2px 0 6px; opacity: .85; }
header nav a { color: #cfe0ff; margin-right: 2px; font-size: 13px; }
main { padding: 4px 22px 40px; max-width: 1500px; }
section { background: #fff; border: 1px solid #ddd; border-radius: 6px; padding: 4px 16px 12px; margin: 14px 0; }
h2 { font-size: 18px; border-bottom: 1px solid #eee; padding-bottom: 4px; } h3 { font-size: 15px; margin: 14px 0 4px; }
table { border-collapse: collapse; margin: 6px 0; }
th, td { border: 1px solid #ddd; padding: 3px 7px; vertical-align: top; }
th { background: #f3f5f8; text-align: left; } table.kv th { width: 12em; }
table.objects td:nth-child(3) { white-space: nowrap; } .renders img { margin-right: 2px; border-radius: 3px; }
td .ok { background: #e5f5e0; padding: 2px 4px; border-radius: 3px; }
td .bad { background: #fde0dd; padding: 2px 4px; border-radius: 3px; }
.rel { color: #1a7f1a; font-weight: 600; } .irr { color: #b22; }
.score { font-variant-numeric: tabular-nums; font-weight: 600; }
.swatch { display: inline-block; width: 10px; height: 10px; margin-right: 5px; border-radius: 2px; }
.missing { color: #777; font-style: italic; } .section-error { color: #b00; font-weight: 600; }
.plots { display: flex; flex-wrap: wrap; gap: 14px; align-items: flex-start; }
svg.plot { background: #fff; border: 1px solid #eee; } svg .frame { fill: none; stroke: #999; }
svg .grid { stroke: #eee; } svg .axis { stroke: #999; } svg .tick, svg .legend { font-size: 10px; fill: #444; }
svg .label { font-size: 11px; fill: #222; } svg .title { font-size: 12px; font-weight: 600; fill: #222; }
svg .ref { stroke: #888; stroke-dasharray: 4 3; } svg .err { stroke: #222; } svg .strip { stroke: #ccc; }
svg .cut { stroke: #000; stroke-width: 2; } svg .pt { stroke: #fff; stroke-width: 1; cursor: pointer; }
svg .pt:hover, svg .bar:hover { stroke: #000; stroke-width: 2; }
svg .err, svg .ref, svg .grid, svg .strip, svg .frame, svg text { pointer-events: none; }
#tip { position: fixed; pointer-events: none; background: #222; color: #fff; padding: 4px 8px; border-radius: 4px;
  font-size: 12px; max-width: 420px; display: none; z-index: 5; }
details { margin: 4px 0; } summary { cursor: pointer; }
.lm-call { border-bottom: 1px solid #eee; padding: 2px 0; }
.lm-call pre, .failure pre { white-space: pre-wrap; margin: 2px 0 6px;
  background: #f6f6f6; padding: 4px 6px; font-size: 12px; max-height: 360px; overflow: auto; }
.hit { color: #1a7f1a; } .miss { color: #b35c00; } .answer pre { background: #eef6ee; }
figure { display: inline-block; margin: 6px; } figure img { max-width: 520px; border: 1px solid #eee; }
"""

SCRIPT = """
(function () {
  var tip = document.getElementById("tip");
  document.addEventListener("mouseover", function (e) {
    var t = e.target.closest ? e.target.closest("[data-tip]") : null;
    if (!t) { tip.style.display = "none"; return; }
    tip.textContent = t.getAttribute("data-tip");
    tip.style.display = "block";
  });
  document.addEventListener("mousemove", function (e) {
    tip.style.left = (e.clientX + 14) + "px";
    tip.style.top = (e.clientY + 12) + "px";
  });
})();
"""


def write_html_report(results: Mapping[str, Any], out_dir: Path, *, command: str = "", lm_record: Path | None = None,
                      render: bool = True, simulator=None, query_curves: Mapping[str, Any] | None = None) -> Path:
    """Write ``out_dir/report.html`` from ``results`` and what the output folder holds (see the module
    docstring). ``lm_record``: the LM call record (default ``out_dir/lm_calls.jsonl``); ``render=False``:
    use only thumbnails already in ``out_dir/renders`` (no Drake); ``query_curves``: the query curves to draw
    (default: ``out_dir/query_curves.json`` when it is there). Returns the path."""
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    page = Report(results, out, command=command, lm_record=lm_record, render=render, simulator=simulator,
                  query_curves=query_curves).html()
    path = out / REPORT
    tmp = path.with_suffix(".tmp")
    tmp.write_text(page, encoding="utf-8")
    tmp.replace(path)
    return path


def regenerate(out_dir: Path, *, render: bool = True, query_curves: Path | None = None) -> Path:
    """``report.html`` again from ``out_dir/results.json`` (``gift report OUT``); ``query_curves``: a query
    curves JSON (``docs/results/queries/curves.json``), copied to ``out_dir/query_curves.json`` so that later
    regenerations draw it too."""
    from gift.core.errors import GiftError

    path = Path(out_dir) / "results.json"
    if not path.is_file():
        raise GiftError(f"no results.json in {out_dir}: give the output folder of gift demo or gift reproduce")
    if query_curves is not None:
        try:
            curves = json.loads(Path(query_curves).read_text())
        except (OSError, ValueError) as e:
            raise GiftError(f"cannot read the query curves {query_curves}: {e}") from e
        if not isinstance(curves, Mapping) or not ("runs" in curves or "curves" in curves):
            raise GiftError(f"{query_curves} is not a query curves file (no 'runs' or 'curves'): give the JSON "
                            "written by scripts/query_curves.py")
        dest = Path(out_dir) / QUERY_CURVES
        if Path(query_curves).resolve() != dest.resolve():
            dest.write_text(json.dumps(curves, indent=1), encoding="utf-8")
            log.info("query curves copied to %s", dest)
    results = json.loads(path.read_text())
    command = ""
    md = Path(out_dir) / "report.md"
    if md.is_file():  # the command that made the run, as report.md recorded it
        text = md.read_text()
        if "Made by:" in text and "```" in text:
            command = text.split("```", 2)[1].strip()
    return write_html_report(results, out_dir, command=command, render=render)
