"""``python -m validate list``: the registered cases with their descriptions, or (``--rigs``) the
shipped rig, sweep and suspension files by name."""

from __future__ import annotations

from ..statuses import OK, epilog


def add_parser(subparsers) -> None:
    """Register the ``list`` subcommand on the CLI's subparsers."""
    p = subparsers.add_parser("list", help="list the registered cases with their whole descriptions (--rigs: the "
                                           "shipped rigs, sweeps and suspensions)",
                              epilog=epilog("list", ("python -m validate list", "python -m validate list --rigs")))
    p.add_argument("--rigs", action="store_true",
                   help="list the shipped rig, sweep and suspension files instead, each with its name (which every "
                        "command takes in place of the path) and a one-line description")


def run(args) -> int:
    """Per case: its name, tags and source, then its description wrapped at 100 columns."""
    import textwrap

    if args.rigs:
        return _list_shipped()
    from ..suite import registered

    for c in registered(slow=True):
        tags = ",".join(sorted(c.tags))
        print(f"{c.name}  [{tags}]  {c.source}")
        text = " ".join(c.description.split())
        print(textwrap.fill(text, width=100, initial_indent="    ", subsequent_indent="    ",
                            break_on_hyphens=False) if text else "    -")
    return OK


def _list_shipped() -> int:
    """``list --rigs``: per kind, one line per shipped file: its name and description."""
    from ..assets import KINDS, MODELS, description, shipped

    for kind in KINDS:
        files = shipped(kind)
        folders = ", ".join(str(MODELS / f) for f in KINDS[kind])
        print(f"{kind}s, in {folders}:")
        width = max(map(len, files))
        for name, path in files.items():
            print(f"  {name:<{width}}  {description(path, width=96 - width)}")
    return OK
