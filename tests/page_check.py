"""Checks every HTML report's test makes: the page parses, stands alone (nothing outside it is
referenced), and, rendered by headless Chromium, is not blank and shows the numbers it should.

Chromium is Debian's package (``.ci/chromium`` installs it); without it the rendering test is
skipped, unless ``CI`` is set, where it fails.
"""

from __future__ import annotations

import base64
import html
import io
import os
import shutil
import subprocess
import tempfile
from html.parser import HTMLParser
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

CHROMIUM_FLAGS = ("--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
                  "--disable-background-networking", "--disable-component-update", "--disable-sync",
                  "--hide-scrollbars")


class _Page(HTMLParser):
    """Every tag with its attributes, the text, and the embedded images."""

    def __init__(self):
        super().__init__(convert_charrefs=True)
        self.tags: list[tuple[str, dict]] = []
        self.text: list[str] = []
        self.images: list[bytes] = []

    def handle_starttag(self, name, attrs):
        attrs = dict(attrs)
        self.tags.append((name, attrs))
        src = attrs.get("src") or ""
        if name == "img" and src.startswith("data:image/png;base64,"):
            self.images.append(base64.b64decode(src.split(",", 1)[1]))

    def handle_data(self, data):
        self.text.append(data)


def parse(text: str) -> _Page:
    page = _Page()
    page.feed(text)
    page.close()
    return page


def check_self_contained(text: str) -> _Page:
    """The page parses, has no address of another machine, links only to its own anchors, embeds its
    images as PNG data, and has no script, frame, link or object; returns the parsed page."""
    page = parse(text)
    assert text.lstrip().startswith("<!DOCTYPE html>")
    assert "http://" not in text and "https://" not in text
    anchors = {a["id"] for _, a in page.tags if "id" in a}
    for name, attrs in page.tags:
        assert name not in ("script", "iframe", "link", "object", "embed", "base"), name
        if "href" in attrs:
            assert attrs["href"].startswith("#") and attrs["href"][1:] in anchors, attrs["href"]
        if "src" in attrs:
            assert attrs["src"].startswith("data:image/png;base64,"), attrs["src"][:40]
    for image in page.images:
        assert Image.open(io.BytesIO(image)).format == "PNG"
    return page


def page_text(page: _Page) -> str:
    """The page's text with every run of white space as one space."""
    return " ".join(html.unescape(" ".join(page.text)).split())


def chromium() -> str | None:
    """The chromium binary; skips the test without one, fails it without one in CI."""
    found = shutil.which("chromium") or shutil.which("chromium-browser")
    if found is None:
        if os.environ.get("CI"):
            pytest.fail("chromium is missing in CI: .ci/chromium installs it")
        pytest.skip("chromium is not installed (apt-get install chromium, or bash .ci/chromium)")
    return found


def render(path: Path, width: int = 1200, height: int = 1600) -> tuple[np.ndarray, str]:
    """Headless Chromium's screenshot of the page (RGB array) and its DOM after loading."""
    binary = chromium()
    with tempfile.TemporaryDirectory() as tmp:
        shot = Path(tmp) / "shot.png"
        base = [binary, *CHROMIUM_FLAGS, f"--user-data-dir={tmp}/profile", f"--window-size={width},{height}"]
        url = Path(path).resolve().as_uri()
        subprocess.run([*base, f"--screenshot={shot}", url], capture_output=True, timeout=180, check=True)
        dom = subprocess.run([*base, "--dump-dom", url], capture_output=True, text=True, timeout=180, check=True).stdout
        image = np.asarray(Image.open(shot).convert("RGB"), dtype=float)
    return image, dom


def check_not_blank(image: np.ndarray) -> None:
    """A rendered page, not an empty one: some pixels far from the background, in several colours,
    spread over the top of the page (the title, the summary)."""
    grey = image.mean(axis=2)
    background = np.median(grey)
    ink = np.abs(grey - background) > 40.0  # text and lines, not anti-aliasing noise
    assert ink.mean() > 0.005, f"only {ink.mean():.2%} of the pixels differ from the background"
    assert ink[: image.shape[0] // 4].any(axis=1).mean() > 0.1, "nothing drawn in the top quarter"
    colours = np.unique((image[ink] // 32).astype(int), axis=0)
    assert len(colours) >= 3, "the page is drawn in fewer than three colours"
