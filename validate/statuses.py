"""The exit statuses of ``python -m validate``: what each means, and which each command can return.

The one source that :func:`validate.cli.main` returns and every command's ``--help`` prints
(:func:`epilog`), so that the help cannot promise a status the command does not have, or hide one.
"""

from __future__ import annotations

OK, CHECK_FAILED, BAD_INPUT, WENT_SLACK, RUN_FAILED, INTERRUPTED, BROKEN_PIPE = 0, 1, 2, 3, 4, 130, 141


class RunFailed(Exception):
    """A run that failed (exit status :data:`RUN_FAILED`): the message is the whole line after ``error: ``.
    Here rather than in :mod:`validate.cli`, so that the commands raising it need not import the CLI."""


MEANING = {
    OK: "success",
    CHECK_FAILED: "a validation check failed",
    BAD_INPUT: "bad input: one line on stderr naming the file (or option), the field and the problem; or an "
               "output that cannot be written (a file, a folder, stdout): one line naming it and the reason",
    WENT_SLACK: "a wire went slack and the taut-wire Kane model stopped there (the CSV ends there)",
    RUN_FAILED: "a run that failed: a numerical failure inside the physics or a spent work budget (one line "
                "naming the field most likely responsible)",
    INTERRUPTED: "interrupted (Ctrl-C)",
    BROKEN_PIPE: "the reader of stdout went away (e.g. '| head'); nothing more is printed",
}

_EVERY = (OK, BAD_INPUT, RUN_FAILED, INTERRUPTED, BROKEN_PIPE)

# Per command: its statuses, and where a command gives a status a narrower meaning, that meaning.
COMMANDS: dict[str, dict[int, str]] = {
    "all": {**dict.fromkeys(_EVERY, ""), CHECK_FAILED: "a case failed: a metric outside its tolerance, or a case "
                                                       "that raised (the table says which)"},
    "case": {**dict.fromkeys(_EVERY, ""), CHECK_FAILED: "the case failed: a metric outside its tolerance, or "
                                                        "the case raised"},
    "list": dict.fromkeys((OK, BAD_INPUT, INTERRUPTED, BROKEN_PIPE), ""),
    "modes": dict.fromkeys(_EVERY, ""),
    "simulate": {**dict.fromkeys(_EVERY, ""), WENT_SLACK: ""},
    "mjcf": dict.fromkeys(_EVERY, ""),
    "identify": dict.fromkeys(_EVERY, ""),
    "calibrate": dict.fromkeys(_EVERY, ""),
    "boat": dict.fromkeys(_EVERY, ""),
    "tensor": dict.fromkeys(_EVERY, ""),
    "plan": dict.fromkeys(_EVERY, ""),
    "sweep": {**dict.fromkeys(_EVERY, ""), CHECK_FAILED: "--check-mujoco: a configuration's MuJoCo periods "
                                                         "differ from the sweep's by more than 1e-6"},
}


def epilog(command: str | None = None, examples: tuple[str, ...] = ()) -> str:
    """The ``exit status:`` block of a command's help (every status, for ``command`` None), wrapped
    to 100 columns, and an ``examples:`` block if ``examples`` are given."""
    import textwrap

    statuses = COMMANDS[command] if command else {}
    lines = ["exit status:"]
    for code in sorted(statuses or MEANING):
        text = statuses.get(code) or MEANING[code]
        if command is None and code in (CHECK_FAILED, WENT_SLACK):
            text += {CHECK_FAILED: " (all, case, sweep --check-mujoco)", WENT_SLACK: " (simulate)"}[code]
        lines += textwrap.wrap(text, width=100, initial_indent=f"  {code:<4} ", subsequent_indent=" " * 7)
    if examples:
        lines += ["", "examples:"] + [f"  {e}" for e in examples]
    return "\n".join(lines) + "\n"
