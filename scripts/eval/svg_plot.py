"""Minimal SVG line plots (standard library only) for docs/results.md."""
import math
from xml.sax.saxutils import escape

COLORS = ["#1f77b4", "#d62728", "#2ca02c", "#9467bd"]


def _ticks(lo, hi, log):
    if log:
        a, b = math.floor(math.log10(lo)), math.ceil(math.log10(hi))
        for mants in ((1, 2, 5), (1, 2, 3, 4, 5, 6, 7, 8, 9)):
            ticks = [m * 10.0 ** e for e in range(a, b + 1) for m in mants if lo <= m * 10.0 ** e <= hi]
            if len(ticks) >= 3:
                break
        return ticks
    step = 10 ** math.floor(math.log10((hi - lo) or 1.0))
    while (hi - lo) / step > 8:
        step *= 2
    v = math.ceil(lo / step) * step
    out = []
    while v <= hi + 1e-12:
        out.append(v)
        v += step
    return out


def _fmt(v):
    if v == 0:
        return "0"
    if abs(v) >= 100 or abs(v) < 0.01:
        return f"{v:.0e}".replace("e-0", "e-").replace("e+0", "e")
    return f"{v:g}"


def plot(series, title, xlabel, ylabel, logx=False, logy=False, width=640, height=400):
    """series: [{"name", "points": [(x, y, label)]}]. Returns SVG text."""
    xs = [p[0] for s in series for p in s["points"]]
    ys = [p[1] for s in series for p in s["points"]]
    if not xs:
        raise ValueError("empty plot")

    def pad(lo, hi, log):
        if log:
            lo, hi = max(lo, 1e-9), max(hi, 1e-9)
            if hi <= lo * 1.01:
                lo, hi = lo / 2, hi * 2
            return lo / 1.3, hi * 1.3
        if hi - lo < 1e-12:
            return lo - 1, hi + 1
        d = (hi - lo) * 0.08
        return lo - d, hi + d

    x0, x1 = pad(min(xs), max(xs), logx)
    y0, y1 = pad(min(ys), max(ys), logy)
    L, R, T, B = 70, 55, 40, 55
    pw, ph = width - L - R, height - T - B

    def tx(x):
        f = (math.log10(x) - math.log10(x0)) / (math.log10(x1) - math.log10(x0)) if logx else (x - x0) / (x1 - x0)
        return L + f * pw

    def ty(y):
        f = (math.log10(y) - math.log10(y0)) / (math.log10(y1) - math.log10(y0)) if logy else (y - y0) / (y1 - y0)
        return T + ph - f * ph

    o = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{width}" height="{height}" '
         f'font-family="sans-serif" font-size="11">',
         f'<rect width="{width}" height="{height}" fill="white"/>',
         f'<text x="{width / 2}" y="18" text-anchor="middle" font-size="13">{escape(title)}</text>',
         f'<rect x="{L}" y="{T}" width="{pw}" height="{ph}" fill="none" stroke="#444"/>']
    for v in _ticks(x0, x1, logx):
        X = tx(v)
        o.append(f'<line x1="{X:.1f}" y1="{T}" x2="{X:.1f}" y2="{T + ph}" stroke="#ddd"/>')
        o.append(f'<text x="{X:.1f}" y="{T + ph + 15}" text-anchor="middle">{_fmt(v)}</text>')
    for v in _ticks(y0, y1, logy):
        Y = ty(v)
        o.append(f'<line x1="{L}" y1="{Y:.1f}" x2="{L + pw}" y2="{Y:.1f}" stroke="#ddd"/>')
        o.append(f'<text x="{L - 5}" y="{Y + 4:.1f}" text-anchor="end">{_fmt(v)}</text>')
    o.append(f'<text x="{L + pw / 2}" y="{height - 12}" text-anchor="middle">{escape(xlabel)}</text>')
    o.append(f'<text transform="translate(16 {T + ph / 2}) rotate(-90)" text-anchor="middle">{escape(ylabel)}</text>')
    for i, s in enumerate(series):
        c = COLORS[i % len(COLORS)]
        pts = s["points"]  # in sweep order
        path = " ".join(f"{tx(x):.1f},{ty(y):.1f}" for x, y, _ in pts)
        o.append(f'<polyline points="{path}" fill="none" stroke="{c}" stroke-width="1.8"/>')
        for x, y, label in pts:
            o.append(f'<circle cx="{tx(x):.1f}" cy="{ty(y):.1f}" r="3.2" fill="{c}"/>')
            o.append(f'<text x="{tx(x) + 5:.1f}" y="{ty(y) - 5 + 12 * i:.1f}" fill="{c}" font-size="10">'
                     f'{escape(label)}</text>')
        o.append(f'<rect x="{L + pw - 230}" y="{T + 8 + 16 * i}" width="10" height="10" fill="{c}"/>')
        o.append(f'<text x="{L + pw - 215}" y="{T + 17 + 16 * i}">{escape(s["name"])}</text>')
    o.append("</svg>")
    return "\n".join(o) + "\n"
