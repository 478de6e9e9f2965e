"""argparse pieces whose errors are one line naming the option (the CLI prints them, exit 2)."""

from __future__ import annotations

import argparse
import math


def positive_float(name: str):
    """A finite number > 0."""

    def parse(text: str) -> float:
        try:
            value = float(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"{name} must be a number, got {text!r}") from None
        if not math.isfinite(value) or value <= 0.0:
            raise argparse.ArgumentTypeError(f"{name} must be a positive finite number, got {text!r}")
        return value

    return parse


def whole_number(name: str, minimum: int):
    """An integer >= ``minimum``."""

    def parse(text: str) -> int:
        try:
            value = int(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"{name} must be a whole number, got {text!r}") from None
        if value < minimum:
            raise argparse.ArgumentTypeError(f"{name} must be at least {minimum}, got {value}")
        return value

    return parse


class UsageError(Exception):
    """Bad command-line input; printed as one line, exit status 2."""


class OneLineParser(argparse.ArgumentParser):
    """Reports a usage error as one line (:class:`UsageError`) instead of usage text and exit."""

    def error(self, message):  # one line instead of usage + message
        raise UsageError(f"{self.prog}: {message}")
