"""A page: a title, a line under it, a table of contents and sections, written whole or not at all.

A :class:`Section` renders its own body; the page wraps each in a collapsible block with an anchor
that the table of contents links to, and inlines its one style sheet. Nothing on the page refers to
anything outside it (no scripts, no fonts, no links but to its own anchors), so it opens from a file
on a machine with no network and stays readable when printed.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

from ..trajectory import atomic_write_text
from .html import Raw, esc, join, slug, tag

STYLE = """
body { font-family: system-ui, -apple-system, "Segoe UI", sans-serif; margin: 0 auto; max-width: 1100px;
       padding: 1em 2em; color: #1e1e1e; background: #fff; line-height: 1.4; }
h1 { font-size: 1.6em; margin-bottom: 0.1em; }
p.subtitle { color: #555; margin-top: 0; }
nav { font-size: 0.9em; columns: 3; margin: 1em 0; }
nav a { display: block; }
details.section { border-top: 1px solid #ccc; padding: 0.4em 0; }
details.section > summary { cursor: pointer; font-size: 1.2em; font-weight: 600; }
details.section details.section > summary { font-size: 1.05em; }
details.section details.section { margin-left: 1em; }
table { border-collapse: collapse; margin: 0.5em 0; font-size: 0.9em; }
th, td { border: 1px solid #ddd; padding: 0.2em 0.5em; text-align: left; vertical-align: top; }
th { background: #f3f3f3; }
td.num, th.num { text-align: right; font-variant-numeric: tabular-nums; }
tr.fail td { background: #fde8e8; }
.pass { color: #17672d; font-weight: 600; }
.fail, .FAIL { color: #b3141b; font-weight: 600; }
.verdict { font-size: 1.3em; }
ul.warnings li { color: #8a4b00; }
pre { background: #f6f6f6; padding: 0.5em; overflow-x: auto; font-size: 0.85em; }
figure { margin: 0.5em 0; }
figure img { max-width: 100%; height: auto; border: 1px solid #eee; }
figcaption { font-size: 0.85em; color: #555; }
"""


class Section:
    """One part of a page: its ``title``, whether it starts ``open``, and :meth:`body` (HTML)."""

    title: str
    open: bool

    @property
    def anchor(self) -> str:
        return slug(self.title)

    def body(self) -> str:
        raise NotImplementedError

    def html(self) -> Raw:
        return tag("details", join([tag("summary", self.title), Raw(self.body())]), cls="section", id=self.anchor,
                   open="" if self.open else None)


@dataclass
class Page:
    """A title, a line under it and the sections, in order."""

    title: str
    subtitle: str = ""
    sections: list[Section] = field(default_factory=list)

    def add(self, *sections: Section) -> "Page":
        self.sections.extend(s for s in sections if s is not None)
        return self

    def html(self) -> str:
        anchors = [s.anchor for s in self.sections]
        if len(set(anchors)) != len(anchors):
            raise ValueError(f"{self.title}: two sections share an anchor")
        nav = tag("nav", join(tag("a", s.title, href=f"#{s.anchor}") for s in self.sections))
        head = join([Raw('<meta charset="utf-8">'), tag("title", self.title), tag("style", Raw(STYLE))])
        body = join([tag("h1", self.title), tag("p", self.subtitle, cls="subtitle") if self.subtitle else "", nav,
                     *(s.html() for s in self.sections)])
        return f"<!DOCTYPE html>\n<html lang=\"en\">\n{tag('head', head)}\n{tag('body', body)}\n</html>\n"

    def write(self, path: str | Path) -> Path:
        """Write the page to ``path`` whole or not at all; returns the path."""
        atomic_write_text(path, self.html())
        return Path(path)
