"""HTML fragments: escaped text, tables, inline PNG figures and numbers as the reports print them.

Every function returns a string of HTML; text passed in is escaped, except a :class:`Raw` fragment.
"""

from __future__ import annotations

import base64
import html
import math
import re
from collections.abc import Iterable, Sequence


class Raw(str):
    """A fragment of HTML that is inserted as it is (not escaped)."""


def esc(value) -> str:
    """``value`` as HTML text: a :class:`Raw` fragment unchanged, anything else escaped."""
    return value if isinstance(value, Raw) else html.escape(str(value), quote=True)


def tag(name: str, content="", **attributes) -> Raw:
    """``<name attributes>content</name>``; attributes with value None are left out, ``cls`` is ``class``."""
    attrs = "".join(f' {"class" if k == "cls" else k.replace("_", "-")}="{esc(v)}"'
                    for k, v in attributes.items() if v is not None)
    return Raw(f"<{name}{attrs}>{esc(content)}</{name}>")


def join(parts: Iterable) -> Raw:
    return Raw("".join(esc(p) for p in parts))


def table(header: Sequence, rows: Iterable[Sequence], row_classes: Iterable[str | None] | None = None,
          cls: str | None = None) -> Raw:
    """A table with one header row; ``row_classes`` gives each body row a class (e.g. ``fail``)."""
    rows = list(rows)
    classes = list(row_classes) if row_classes is not None else [None] * len(rows)
    head = tag("tr", join(tag("th", h) for h in header))
    body = join(tag("tr", join(tag("td", c) for c in row), cls=k) for row, k in zip(rows, classes))
    return tag("table", join([tag("thead", head), tag("tbody", body)]), cls=cls)


def png(data: bytes, alt: str) -> Raw:
    """An image inside the page: the PNG's bytes as a ``data:`` URI."""
    return Raw(f'<img alt="{esc(alt)}" src="data:image/png;base64,{base64.b64encode(data).decode()}">')


def number(value, digits: int = 4, unit: str = "") -> str:
    """A number as the reports print it: ``digits`` significant digits, "-" for None, "nan"/"inf" as such."""
    if value is None:
        return "-"
    value = float(value)
    text = f"{value:.{digits}g}" if math.isfinite(value) else str(value)
    return f"{text} {unit}" if unit else text


def slug(text: str) -> str:
    """An HTML id from ``text``: lower case letters, digits, '-', '.' and '_'."""
    return re.sub(r"[^a-z0-9._-]+", "-", text.lower()).strip("-") or "section"
