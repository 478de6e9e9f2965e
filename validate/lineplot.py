"""Line plots as small PNG files, drawn with Pillow (installed with rerun-sdk): a figure for a
document without a plotting library.

A figure is panels stacked vertically over one shared x axis; each panel has its own y axis (ticks
at 1, 2 or 5 times a power of ten), a title, a legend, line series (solid or dashed) and thin
horizontal reference levels. The image is saved with an adaptive palette, which keeps a figure of a
few thousand points to some tens of kB.
"""

from __future__ import annotations

import io
import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from PIL import Image, ImageDraw, ImageFont

from .trajectory import atomic_write_bytes

WIDTH = 960  # px
PANEL_HEIGHT = 250  # px, plotting area and title of one panel
MARGIN = (80, 20, 30, 50)  # px: left (y labels), right, top of each panel (title), bottom (x labels)
DASH = 6  # samples drawn, then skipped, in a dashed series
FONT_SIZE = 14
GRID_RGB = (225, 225, 225)
AXIS_RGB = (60, 60, 60)


@dataclass(frozen=True)
class Series:
    x: np.ndarray
    y: np.ndarray
    label: str  # "" keeps the series out of the legend
    rgb: tuple[int, int, int]
    dashed: bool = False


@dataclass(frozen=True)
class Panel:
    title: str
    ylabel: str
    series: tuple[Series, ...]
    levels: tuple[tuple[float, tuple[int, int, int]], ...] = field(default_factory=tuple)  # (y, colour)


def nice_ticks(low: float, high: float, count: int = 5) -> np.ndarray:
    """Ticks covering [low, high]: the smallest step of 1, 2 or 5 times a power of ten that is at least
    (high - low) / ``count``."""
    if high <= low:
        high = low + 1.0
    raw = (high - low) / count
    power = 10.0 ** math.floor(math.log10(raw))
    step = next(m * power for m in (1.0, 2.0, 5.0, 10.0) if m * power >= raw)
    return np.arange(math.floor(low / step), math.ceil(high / step) + 1) * step


def save_png(path: str | Path, panels: list[Panel], xlabel: str) -> Path:
    """Draw the panels over a shared x range and write the PNG (:func:`render_png`); returns the path."""
    path = Path(path)
    atomic_write_bytes(path, render_png(panels, xlabel))
    return path


def render_png(panels: list[Panel], xlabel: str) -> bytes:
    """The panels drawn over a shared x range, as the bytes of a PNG file."""
    font = ImageFont.load_default(size=FONT_SIZE)
    left, right, top, bottom = MARGIN
    height = len(panels) * (PANEL_HEIGHT + top) + bottom
    image = Image.new("RGB", (WIDTH, height), "white")
    draw = ImageDraw.Draw(image)
    xs = np.concatenate([s.x for p in panels for s in p.series])
    xticks = nice_ticks(float(xs.min()), float(xs.max()))
    x0, x1 = xticks[0], xticks[-1]
    for k, panel in enumerate(panels):
        y_top = k * (PANEL_HEIGHT + top) + top
        box = (left, y_top, WIDTH - right, y_top + PANEL_HEIGHT - top)
        ys = np.concatenate([s.y for s in panel.series] + [np.array([v for v, _ in panel.levels])])
        yticks = nice_ticks(float(ys.min()), float(ys.max()))
        y0, y1 = yticks[0], yticks[-1]

        def px(x, y):
            u = box[0] + (np.asarray(x) - x0) / (x1 - x0) * (box[2] - box[0])
            v = box[3] - (np.asarray(y) - y0) / (y1 - y0) * (box[3] - box[1])
            return u, v

        for t in yticks:
            _, v = px(x0, t)
            draw.line([(box[0], v), (box[2], v)], fill=GRID_RGB)
            draw.text((box[0] - 6, v), f"{t:g}", fill=AXIS_RGB, font=font, anchor="rm")
        for t in xticks:
            u, _ = px(t, y0)
            draw.line([(u, box[1]), (u, box[3])], fill=GRID_RGB)
            if k == len(panels) - 1:
                draw.text((u, box[3] + 6), f"{t:g}", fill=AXIS_RGB, font=font, anchor="mt")
        for value, rgb in panel.levels:
            _, v = px(x0, value)
            draw.line([(box[0], v), (box[2], v)], fill=rgb, width=1)
        for s in panel.series:
            u, v = px(s.x, s.y)
            points = list(zip(u.tolist(), v.tolist()))
            step = 2 * DASH if s.dashed else len(points)
            for i in range(0, len(points), step):
                draw.line(points[i : i + (DASH + 1 if s.dashed else step)], fill=s.rgb, width=2)
        draw.rectangle(box, outline=AXIS_RGB)
        draw.text((box[0], y_top - 6), panel.title, fill=AXIS_RGB, font=font, anchor="lb")
        draw.text((box[0] - 6, box[1] - 6), panel.ylabel, fill=AXIS_RGB, font=font, anchor="rb")
        _legend(draw, font, panel, box)
    draw.text((WIDTH - right, height - 8), xlabel, fill=AXIS_RGB, font=font, anchor="rb")
    png = io.BytesIO()
    image.quantize(colors=64).save(png, format="PNG", optimize=True)
    return png.getvalue()


def _legend(draw: ImageDraw.ImageDraw, font, panel: Panel, box) -> None:
    """One line per labelled series in the panel's top right corner, on white."""
    rows = [(s.label, s.rgb, s.dashed) for s in panel.series if s.label]
    width = max(draw.textlength(label, font=font) for label, _, _ in rows) + 40
    x, y = box[2] - width - 8, box[1] + 6
    draw.rectangle((x - 4, y - 2, box[2] - 6, y + 18 * len(rows) + 2), fill="white", outline=GRID_RGB)
    for i, (label, rgb, dashed) in enumerate(rows):
        v = y + 18 * i + 9
        for a in range(0, 28, 10 if dashed else 28):
            draw.line([(x + a, v), (x + min(a + (6 if dashed else 28), 28), v)], fill=rgb, width=2)
        draw.text((x + 34, v), label, fill=AXIS_RGB, font=font, anchor="lm")
