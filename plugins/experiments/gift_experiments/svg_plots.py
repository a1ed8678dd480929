"""Small inline SVG plots for the HTML report (no JavaScript library, nothing fetched).

Every mark carries ``data-tip`` (the report's script shows it next to the pointer on hover) and a
``<title>`` child (the browser's own tooltip, also without script). Plots are ``<svg class="plot">``
with ``data-plot`` naming the kind; points are ``<circle class="pt">`` with ``data-label`` = the object.
"""

from __future__ import annotations

import html
import math
from collections.abc import Sequence

import attrs
import numpy as np

#: Colours per kernel (and the label alignment), stable across plots.
KERNEL_COLOURS = {"vision": "#1f77b4", "language": "#ff7f0e", "lm-no-intent": "#9467bd", "gift": "#8c564b",
                  "gift-prob": "#2ca02c", "oracle-labels": "#7f7f7f"}
EXTRA = ("#d62728", "#e377c2", "#bcbd22", "#17becf")
RELEVANT, OTHER = "#2ca02c", "#d62728"


def esc(s) -> str:
    return html.escape(str(s), quote=True)


def colour(name: str, i: int = 0) -> str:
    return KERNEL_COLOURS.get(name, EXTRA[i % len(EXTRA)])


def _ticks(lo: float, hi: float, n: int = 5) -> list[float]:
    if not (math.isfinite(lo) and math.isfinite(hi)) or hi <= lo:
        return [lo]
    raw = (hi - lo) / n
    mag = 10 ** math.floor(math.log10(raw))
    step = min((m * mag for m in (1, 2, 2.5, 5, 10) if m * mag >= raw), default=raw)
    start = math.ceil(lo / step - 1e-9) * step
    return [round(start + k * step, 10) for k in range(int((hi - start) / step + 1e-9) + 1)]


@attrs.frozen
class _Frame:
    """Data -> pixel mapping of one plot area."""

    width: int
    height: int
    left: int
    right: int
    top: int
    bottom: int
    xlim: tuple[float, float]
    ylim: tuple[float, float]

    def x(self, v: float) -> float:
        a, b = self.xlim
        return self.left + (v - a) / (b - a) * (self.width - self.left - self.right)

    def y(self, v: float) -> float:
        a, b = self.ylim
        return self.height - self.bottom - (v - a) / (b - a) * (self.height - self.top - self.bottom)

    def axes(self, xlabel: str, ylabel: str, xticks: bool = True) -> list[str]:
        x0, x1 = self.left, self.width - self.right
        y0, y1 = self.height - self.bottom, self.top
        out = [f'<rect x="{x0}" y="{y1}" width="{x1 - x0}" height="{y0 - y1}" class="frame"/>']
        for t in _ticks(*self.ylim):
            yy = self.y(t)
            out.append(f'<line x1="{x0 - 4}" x2="{x1}" y1="{yy:.1f}" y2="{yy:.1f}" class="grid"/>'
                       f'<text x="{x0 - 6}" y="{yy + 4:.1f}" class="tick" text-anchor="end">{t:g}</text>')
        if xticks:
            for t in _ticks(*self.xlim):
                xx = self.x(t)
                out.append(f'<line x1="{xx:.1f}" x2="{xx:.1f}" y1="{y0}" y2="{y0 + 4}" class="axis"/>'
                           f'<text x="{xx:.1f}" y="{y0 + 16}" class="tick" text-anchor="middle">{t:g}</text>')
        if xlabel:
            out.append(f'<text x="{(x0 + x1) / 2:.1f}" y="{self.height - 4}" class="label" '
                       f'text-anchor="middle">{esc(xlabel)}</text>')
        if ylabel:
            out.append(f'<text transform="translate(13 {(y0 + y1) / 2:.1f}) rotate(-90)" class="label" '
                       f'text-anchor="middle">{esc(ylabel)}</text>')
        return out


def _svg(kind: str, width: int, height: int, body: Sequence[str], title: str = "") -> str:
    head = f'<text x="{width / 2:.0f}" y="14" class="title" text-anchor="middle">{esc(title)}</text>' if title else ""
    return (f'<svg class="plot" data-plot="{esc(kind)}" xmlns="http://www.w3.org/2000/svg" width="{width}" '
            f'height="{height}" viewBox="0 0 {width} {height}" role="img">{head}{"".join(body)}</svg>')


def _tip(text: str) -> tuple[str, str]:
    """``(attribute, child)``: the data-tip attribute and the <title> element of a mark."""
    return f' data-tip="{esc(text)}"', f"<title>{esc(text)}</title>"


def bar_chart(groups: Sequence[str], series: Sequence[str], mean: np.ndarray, se: np.ndarray | None = None, *,
              tips: Sequence[Sequence[str]] | None = None, ylabel: str = "", title: str = "",
              ylim: tuple[float, float] = (0.0, 1.0), ref: float | None = None, kind: str = "bars") -> str:
    """Grouped bars: ``mean``/``se`` ``[n_series, n_groups]`` (NaN: no bar); ``tips[s][g]`` hover texts."""
    mean = np.asarray(mean, dtype=float).reshape(len(series), len(groups))
    legend_w = 16 + 6.5 * max((len(s) for s in series), default=0)
    width = int(max(520, 60 + legend_w + len(groups) * (18 * len(series) + 26)))
    f = _Frame(width, 250, 48, int(legend_w) + 14, 24 if title else 10, 58, (0.0, float(len(groups))), ylim)
    body = f.axes("", ylabel, xticks=False)
    bw = 0.8 / max(len(series), 1)
    for g, name in enumerate(groups):
        body.append(f'<text transform="translate({f.x(g + 0.5):.1f} {f.height - f.bottom + 12}) rotate(18)" '
                    f'class="tick">{esc(name)}</text>')
        for s, sname in enumerate(series):
            m = mean[s, g]
            if not np.isfinite(m):
                continue
            x0 = f.x(g + 0.1 + s * bw)
            x1 = f.x(g + 0.1 + (s + 1) * bw)
            e = float(se[s][g]) if se is not None and np.isfinite(se[s][g]) else None
            tip = tips[s][g] if tips else f"{name} / {sname}: {m:.3f}" + (f" ± {e:.3f}" if e else "")
            attr, title_el = _tip(tip)
            y = f.y(min(max(m, ylim[0]), ylim[1]))
            body.append(f'<rect class="bar" data-series="{esc(sname)}" data-group="{esc(name)}"{attr} '
                        f'x="{x0:.1f}" y="{y:.1f}" width="{max(x1 - x0 - 1, 1):.1f}" '
                        f'height="{f.y(ylim[0]) - y:.1f}" fill="{colour(sname, s)}">{title_el}</rect>')
            if e:
                xc = (x0 + x1) / 2
                body.append(f'<line class="err" x1="{xc:.1f}" x2="{xc:.1f}" y1="{f.y(min(m + e, ylim[1])):.1f}" '
                            f'y2="{f.y(max(m - e, ylim[0])):.1f}"/>')
    if ref is not None:
        body.append(f'<line class="ref" x1="{f.left}" x2="{f.width - f.right}" y1="{f.y(ref):.1f}" '
                    f'y2="{f.y(ref):.1f}"/>')
    body.append(_legend(series, f.width - f.right + 10, f.top + 4))
    return _svg(kind, width, 250, body, title)


def _legend(series: Sequence[str], x: float, y: float, colours: Sequence[str] | None = None) -> str:
    items = []
    for i, s in enumerate(series):
        c = colours[i] if colours else colour(s, i)
        items.append(f'<rect x="{x:.0f}" y="{y + 13 * i:.0f}" width="9" height="9" fill="{c}"/>'
                     f'<text x="{x + 13:.0f}" y="{y + 13 * i + 8:.0f}" class="legend">{esc(s)}</text>')
    return f'<g class="legend">{"".join(items)}</g>'


@attrs.frozen
class Point:
    """A point of :func:`scatter` / :func:`strips`: ``label`` names it (the object); ``relevant`` colours it."""

    x: float
    y: float
    label: str
    relevant: bool
    tip: str = ""


def scatter(points: Sequence[Point], *, xlabel: str, ylabel: str, title: str = "",
            anchor: tuple[float, float, str] | None = None, kind: str = "scatter") -> str:
    """Points coloured by relevance (green relevant, red not); ``anchor`` (x, y, name) as a star."""
    xs = [p.x for p in points] + ([anchor[0]] if anchor else [])
    ys = [p.y for p in points] + ([anchor[1]] if anchor else [])
    pad = lambda lo, hi: (lo - 0.06 * max(hi - lo, 0.05), hi + 0.06 * max(hi - lo, 0.05))  # noqa: E731
    f = _Frame(420, 360, 48, 14, 24 if title else 10, 38, pad(min(xs), max(xs)), pad(min(ys), max(ys)))
    body = f.axes(xlabel, ylabel)
    for p in points:
        attr, title_el = _tip(p.tip or f"{p.label}: ({p.x:.3f}, {p.y:.3f})")
        body.append(f'<circle class="pt" data-label="{esc(p.label)}"{attr} cx="{f.x(p.x):.1f}" cy="{f.y(p.y):.1f}" '
                    f'r="5" fill="{RELEVANT if p.relevant else OTHER}">{title_el}</circle>')
    if anchor:
        attr, title_el = _tip(f"anchor (training object): {anchor[2]}")
        cx, cy = f.x(anchor[0]), f.y(anchor[1])
        star = " ".join(f"{cx + r * math.sin(a):.1f},{cy - r * math.cos(a):.1f}"
                        for k in range(10) for a, r in [(k * math.pi / 5, 8 if k % 2 == 0 else 3.5)])
        body.append(f'<polygon class="anchor"{attr} points="{star}" fill="black">{title_el}</polygon>')
    body.append(_legend(["relevant", "not relevant"], f.left + 8, f.top + 6, [RELEVANT, OTHER]))
    return _svg(kind, 420, 360, body, title)


@attrs.frozen
class StripRow:
    """One kernel of :func:`strips`: its points (``x`` = decision score) and its cut."""

    name: str
    cut: float | None
    points: tuple[Point, ...]


def strips(rows: Sequence[StripRow], *, xlabel: str = "decision score", title: str = "",
           kind: str = "decisions") -> str:
    """One horizontal strip per kernel: each object at its score (jittered vertically), the cut as a line."""
    values = [p.x for r in rows for p in r.points] + [r.cut for r in rows if r.cut is not None]
    lo, hi = (min(values), max(values)) if values else (0.0, 1.0)
    lo, hi = min(lo, 0.0), max(hi, 1.0)
    height = 44 + 46 * len(rows) + (16 if title else 0)
    f = _Frame(560, height, 96, 14, 24 if title else 8, 36, (lo, hi), (0.0, float(len(rows))))
    body = []
    x0, x1 = f.left, f.width - f.right
    for t in _ticks(lo, hi):
        body.append(f'<line x1="{f.x(t):.1f}" x2="{f.x(t):.1f}" y1="{f.top}" y2="{f.height - f.bottom}" '
                    f'class="grid"/><text x="{f.x(t):.1f}" y="{f.height - f.bottom + 14}" class="tick" '
                    f'text-anchor="middle">{t:g}</text>')
    body.append(f'<text x="{(x0 + x1) / 2:.0f}" y="{f.height - 4}" class="label" text-anchor="middle">'
                f'{esc(xlabel)}</text>')
    rng = np.random.default_rng(0)
    for i, r in enumerate(rows):
        yc = f.y(len(rows) - i - 0.5)
        body.append(f'<text x="{x0 - 6}" y="{yc + 4:.1f}" class="tick" text-anchor="end">{esc(r.name)}</text>'
                    f'<line class="strip" x1="{x0}" x2="{x1}" y1="{yc:.1f}" y2="{yc:.1f}"/>')
        if r.cut is not None:
            attr, title_el = _tip(f"{r.name}: cut {r.cut:.3f}")
            body.append(f'<line class="cut"{attr} x1="{f.x(r.cut):.1f}" x2="{f.x(r.cut):.1f}" y1="{yc - 18:.1f}" '
                        f'y2="{yc + 18:.1f}">{title_el}</line>')
        for p, j in zip(r.points, rng.uniform(-11, 11, size=len(r.points))):
            attr, title_el = _tip(p.tip or f"{p.label}: {p.x:.3f}")
            body.append(f'<circle class="pt" data-label="{esc(p.label)}" data-series="{esc(r.name)}"{attr} '
                        f'cx="{f.x(p.x):.1f}" cy="{yc + j:.1f}" r="4.5" '
                        f'fill="{RELEVANT if p.relevant else OTHER}">{title_el}</circle>')
    return _svg(kind, 560, height, body, title)


@attrs.frozen
class Line:
    """One curve of :func:`lines`: ``y`` per x (None: no point), an optional ± ``band``, and hover texts."""

    name: str
    y: tuple[float | None, ...]
    band: tuple[float | None, ...] | None = None
    tips: tuple[str, ...] = ()
    dashed: bool = False
    colour: str = ""


def lines(x: Sequence[float], curves: Sequence[Line], *, xlabel: str = "", ylabel: str = "", title: str = "",
          ylim: tuple[float, float] | None = None, kind: str = "lines") -> str:
    """A line with a dot per x for each curve (its ± band shaded, a dot's hover text from ``tips``); ``ylim``:
    the data range, padded, when None."""
    ys = []
    for c in curves:
        for j, v in enumerate(c.y):
            if v is not None:
                b = (c.band[j] if c.band else None) or 0.0
                ys += [v - b, v + b]
    if ylim is None:
        lo, hi = (min(ys), max(ys)) if ys else (0.0, 1.0)
        pad = 0.08 * max(hi - lo, 0.05)
        ylim = (lo - pad, hi + pad)
    legend_w = 16 + 6.5 * max((len(c.name) for c in curves), default=0)
    width = int(340 + legend_w)
    xs = [float(v) for v in x]
    f = _Frame(width, 250, 56, int(legend_w) + 14, 24 if title else 10, 38,
               (min(xs), max(xs)) if len(xs) > 1 and max(xs) > min(xs) else (0.0, 1.0), ylim)
    body = f.axes(xlabel, ylabel, xticks=False)
    y0 = f.height - f.bottom
    for v in xs:
        body.append(f'<line x1="{f.x(v):.1f}" x2="{f.x(v):.1f}" y1="{y0}" y2="{y0 + 4}" class="axis"/>'
                    f'<text x="{f.x(v):.1f}" y="{y0 + 16}" class="tick" text-anchor="middle">{v:g}</text>')
    for i, c in enumerate(curves):
        col = c.colour or colour(c.name, i)
        pts = [(f.x(a), v, b) for a, v, b in zip(xs, c.y, c.band or (None,) * len(c.y)) if v is not None]
        if c.band and any(b for _, _, b in pts):
            upper = [f"{px:.1f},{f.y(min(v + (b or 0), ylim[1])):.1f}" for px, v, b in pts]
            lower = [f"{px:.1f},{f.y(max(v - (b or 0), ylim[0])):.1f}" for px, v, b in reversed(pts)]
            body.append(f'<polygon class="band" data-series="{esc(c.name)}" points="{" ".join(upper + lower)}" '
                        f'fill="{col}" fill-opacity="0.18" stroke="none"/>')
        if len(pts) > 1:
            path = " ".join(f"{px:.1f},{f.y(v):.1f}" for px, v, _ in pts)
            dash = ' stroke-dasharray="5 3"' if c.dashed else ""
            body.append(f'<polyline class="curve" data-series="{esc(c.name)}" points="{path}" fill="none" '
                        f'stroke="{col}" stroke-width="2"{dash}/>')
        for j, (a, v) in enumerate(zip(xs, c.y)):
            if v is None:
                continue
            b = c.band[j] if c.band else None
            attr, title_el = _tip(c.tips[j] if j < len(c.tips) else
                                  f"{c.name}: {v:.3f}" + (f" ± {b:.3f}" if b else "") + f" at {a:g}")
            body.append(f'<circle class="pt" data-series="{esc(c.name)}"{attr} cx="{f.x(a):.1f}" cy="{f.y(v):.1f}" '
                        f'r="4" fill="{col}">{title_el}</circle>')
    body.append(_legend([c.name for c in curves], f.width - f.right + 10, f.top + 4,
                        [c.colour or colour(c.name, i) for i, c in enumerate(curves)]))
    return _svg(kind, width, 250, body, title)
