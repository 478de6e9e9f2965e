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


def bounded_float(name: str, low: float, high: float, unit: str, low_open: bool = False):
    """A finite number in ``[low, high]`` (``(low, high]`` with ``low_open``), ``unit`` for the message."""
    unit = f" {unit}" if unit else ""

    def parse(text: str) -> float:
        try:
            value = float(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"{name} must be a number, got {text!r}") from None
        too_low = value <= low if low_open else value < low
        if not math.isfinite(value) or too_low or value > high:
            bracket = "(" if low_open else "["
            raise argparse.ArgumentTypeError(f"{name} must be in {bracket}{low:g}, {high:g}]{unit}, got {text!r}")
        return value

    return parse


def whole_number(name: str, minimum: int, maximum: int | None = None):
    """An integer >= ``minimum`` (and <= ``maximum`` if given); at most 18 digits are read."""

    def parse(text: str) -> int:
        if len(text.strip()) > 18:
            raise argparse.ArgumentTypeError(f"{name} must be a whole number of at most 18 digits, got {text[:20]!r}...")
        try:
            value = int(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"{name} must be a whole number, got {text!r}") from None
        if value < minimum:
            raise argparse.ArgumentTypeError(f"{name} must be at least {minimum}, got {value}")
        if maximum is not None and value > maximum:
            raise argparse.ArgumentTypeError(f"{name} must be at most {maximum}, got {value}")
        return value

    return parse


class UsageError(Exception):
    """Bad command-line input; printed as one line, exit status 2."""


class OneLineParser(argparse.ArgumentParser):
    """Reports a usage error as one line (:class:`UsageError`) instead of usage text and exit; help
    keeps the description's and epilog's line breaks."""

    def __init__(self, *args, **kwargs):
        kwargs.setdefault("formatter_class", argparse.RawDescriptionHelpFormatter)
        super().__init__(*args, **kwargs)

    def error(self, message):  # one line instead of usage + message
        raise UsageError(f"{self.prog}: {message}")
