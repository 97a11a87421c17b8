"""XML in and out for the exchange formats: numbers written at full precision, files read
with the line of every element, errors that name the file, the element and its line.

The standard library does the work (no third-party XML package is needed to write or read
these files): ElementTree builds and writes the trees, expat reads them, telling each
element's line, which ElementTree's own parser does not keep.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
import xml.parsers.expat
from collections.abc import Iterable
from dataclasses import dataclass, field

from .tree import ExchangeError


def num(value: float) -> str:
    """A number at full precision (``repr`` of the double: it reads back exactly)."""
    return repr(float(value)) if value != 0.0 else "0"


def nums(values: Iterable[float]) -> str:
    return " ".join(num(v) for v in values)


def text(root: ET.Element) -> str:
    """The document, indented, with its XML declaration."""
    ET.indent(root, space="  ")
    return '<?xml version="1.0" encoding="utf-8"?>\n' + ET.tostring(root, encoding="unicode") + "\n"


@dataclass
class Document:
    """A parsed file: its root, the line of each element, and the file's name for messages."""

    root: ET.Element
    source: str
    lines: dict[ET.Element, int] = field(default_factory=dict)

    def where(self, el: ET.Element) -> str:
        name = el.get("name")
        return f"{self.source}: line {self.lines.get(el, '?')}: <{el.tag}{f' name={name!r}' if name else ''}>"

    def error(self, el: ET.Element, message: str) -> ExchangeError:
        return ExchangeError(f"{self.where(el)}: {message}")

    def floats(self, el: ET.Element, attr: str, count: int, default: str | None = None) -> list[float]:
        """An attribute of ``count`` numbers, or a clear error."""
        raw = el.get(attr, default)
        if raw is None:
            raise self.error(el, f"attribute {attr!r} is missing")
        try:
            values = [float(v) for v in raw.split()]
        except ValueError:
            raise self.error(el, f"{attr}={raw!r} is not {count} number(s)") from None
        if len(values) != count:
            raise self.error(el, f"{attr}={raw!r} has {len(values)} number(s), {count} expected")
        return values


def parse(data: str, source: str) -> Document:
    """Parse XML text, noting each element's line; a malformed file raises ExchangeError
    with the line and column expat gives."""
    builder = ET.TreeBuilder()
    expat = xml.parsers.expat.ParserCreate()
    lines: dict[ET.Element, int] = {}

    def start(tag: str, attrs: dict[str, str]) -> None:
        lines[builder.start(tag, attrs)] = expat.CurrentLineNumber

    expat.StartElementHandler = start
    expat.EndElementHandler = builder.end
    expat.CharacterDataHandler = builder.data
    try:
        expat.Parse(data, True)
    except xml.parsers.expat.ExpatError as e:
        raise ExchangeError(f"{source}: line {e.lineno} column {e.offset}: not well-formed XML: "
                            f"{xml.parsers.expat.ErrorString(e.code)}") from None
    return Document(builder.close(), source, lines)
