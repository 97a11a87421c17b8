"""XML in and out for the exchange formats: numbers written at full precision, files read
with the line of every element, errors that name the file, the element and its line.

The standard library's ElementTree does the work (no third-party XML package is needed to
write or read these files); its C parser keeps no line numbers, so ``parse`` records them
from expat while the tree is built.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
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


class _LineBuilder(ET.TreeBuilder):
    """A TreeBuilder that notes the line where each element starts."""

    def __init__(self) -> None:
        super().__init__(insert_comments=False)
        self.lines: dict[ET.Element, int] = {}
        self.parser: ET.XMLParser | None = None

    def start(self, tag, attrs):  # type: ignore[no-untyped-def]  # TreeBuilder's own signature
        el = super().start(tag, attrs)
        assert self.parser is not None
        self.lines[el] = self.parser.parser.CurrentLineNumber  # type: ignore[attr-defined]  # expat's
        return el


def parse(data: str, source: str) -> Document:
    """Parse XML text; a malformed file raises ExchangeError with the line expat gives."""
    builder = _LineBuilder()
    parser = ET.XMLParser(target=builder)
    builder.parser = parser
    try:
        parser.feed(data)
        root = parser.close()
    except ET.ParseError as e:
        raise ExchangeError(f"{source}: not well-formed XML: {e}") from None
    return Document(root, source, builder.lines)
