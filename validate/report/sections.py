"""The sections pages are built from: facts, tables, figures, warnings, text, and groups of sections."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

from .html import Raw, join, png, table, tag
from .page import Section


@dataclass
class Facts(Section):
    """Name-value pairs, e.g. what ran where."""

    title: str
    items: Sequence[tuple[str, object]]
    note: str = ""
    open: bool = True

    def body(self) -> str:
        rows = join(tag("tr", join([tag("th", k), tag("td", v)])) for k, v in self.items)
        return join([tag("table", tag("tbody", rows), cls="facts"), tag("p", self.note) if self.note else ""])


@dataclass
class Table(Section):
    """Rows under a header; ``row_classes`` marks rows (``fail``); ``note`` is a line under it."""

    title: str
    header: Sequence[str]
    rows: Sequence[Sequence]
    note: str = ""
    row_classes: Sequence[str | None] | None = None
    open: bool = True

    def body(self) -> str:
        return join([table(self.header, self.rows, self.row_classes), tag("p", self.note) if self.note else ""])


@dataclass
class Figure(Section):
    """One PNG drawn into the page, with its caption."""

    title: str
    image: bytes
    caption: str = ""
    open: bool = True

    def body(self) -> str:
        return figure(self.image, self.caption or self.title)


@dataclass
class Warnings(Section):
    """Things a reader must not miss, one line each; "none" when there are none."""

    title: str
    lines: Sequence[str]
    open: bool = True

    def body(self) -> str:
        if not self.lines:
            return tag("p", "none")
        return tag("ul", join(tag("li", line) for line in self.lines), cls="warnings")


@dataclass
class Text(Section):
    """Paragraphs; a :class:`~validate.report.html.Raw` paragraph goes in as HTML."""

    title: str
    paragraphs: Sequence[str]
    open: bool = True

    def body(self) -> str:
        return join(tag("p", p) for p in self.paragraphs)


@dataclass
class Group(Section):
    """Sections inside one collapsible block, after an optional lead paragraph (HTML)."""

    title: str
    children: Sequence[Section] = field(default_factory=list)
    lead: str = ""
    open: bool = True
    anchor_name: str = ""

    @property
    def anchor(self) -> str:
        return self.anchor_name or super().anchor

    def body(self) -> str:
        return join([Raw(self.lead), *(c.html() for c in self.children)])


def figure(image: bytes, caption: str) -> Raw:
    """An inline PNG with its caption."""
    return tag("figure", join([png(image, caption), tag("figcaption", caption)]))


def verdict(passed: bool | None) -> Raw:
    """PASS / FAIL in its colour (None: no verdict)."""
    if passed is None:
        return Raw("-")
    return tag("span", "PASS" if passed else "FAIL", cls="pass" if passed else "fail")
