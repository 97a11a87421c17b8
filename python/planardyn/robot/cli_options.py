"""argparse types for the robot and planning commands' numeric options: each refuses NaN,
infinities and values outside its range with a message argparse prefixes with the option's
name (``argument --dt: ...``), and the command exits 2."""

from __future__ import annotations

import argparse
import math
from collections.abc import Callable


def number(low: float = -math.inf, high: float = math.inf, *, open_low: bool = False,
           unit: str = "") -> Callable[[str], float]:
    """A finite number in [low, high] ((low, high] with ``open_low``)."""
    where = f"{'>' if open_low else '>='} {low:g}" if math.isfinite(low) else ""
    if math.isfinite(high):
        where = f"{where} and <= {high:g}" if where else f"<= {high:g}"
    want = f"a finite number{' ' + where if where else ''}{f' ({unit})' if unit else ''}"

    def parse(text: str) -> float:
        try:
            value = float(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"{text!r} is not a number: give {want}") from None
        if not (math.isfinite(value) and (low < value if open_low else low <= value) and value <= high):
            raise argparse.ArgumentTypeError(f"{text} is out of range: give {want}")
        return value

    return parse


def positive(unit: str = "") -> Callable[[str], float]:
    """A finite number > 0."""
    return number(0.0, open_low=True, unit=unit)


def integer(low: int, high: int) -> Callable[[str], int]:
    """An integer from low to high."""

    def parse(text: str) -> int:
        try:
            value = int(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"{text!r} is not an integer: give one from {low} to {high}") from None
        if not low <= value <= high:
            raise argparse.ArgumentTypeError(f"{text} is out of range: give an integer from {low} to {high}")
        return value

    return parse
