"""Print the README's set-up commands, one a line: the ```bash blocks under "## Set up and run".

.ci/run runs exactly what this prints, so that CI and the README cannot drift apart; it refuses
(exit 1) a README whose section does not hold exactly two one-line blocks (installing and running
the validation suite, installing and running the tests)."""

from __future__ import annotations

import re
import sys
from pathlib import Path

README = Path(__file__).resolve().parents[1] / "README.md"
SECTION = "## Set up and run"


def commands(text: str) -> list[str]:
    """The commands of the set-up section of the README ``text`` (see the module docstring)."""
    if SECTION not in text:
        raise ValueError(f"README.md has no {SECTION!r} section")
    section = text.split(SECTION, 1)[1].split("\n## ", 1)[0]
    blocks = re.findall(r"```bash\n(.*?)\n```", section, flags=re.S)
    if len(blocks) != 2 or any("\n" in b or not b.strip() for b in blocks):
        raise ValueError(f"README.md's {SECTION!r} must hold two one-line ```bash blocks, found {blocks!r}")
    return [b.strip() for b in blocks]


if __name__ == "__main__":
    try:
        print("\n".join(commands(README.read_text(encoding="utf-8"))))
    except ValueError as exc:
        sys.exit(f"error: {exc}")
