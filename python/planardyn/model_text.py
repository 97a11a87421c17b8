"""A model dict as the text of a YAML model file, one line per point, body, pair and
coordinate, floats at full precision: what :func:`planardyn.library.write_model` and
:meth:`planardyn.builder.Builder.write` write (no YAML library needed to write it; ``yaml.safe_load``
reads it back)."""

from __future__ import annotations

import json
import math
import re
from collections.abc import Mapping
from typing import Any

from .arguments import error

_PLAIN = re.compile(r"^[A-Za-z_][A-Za-z0-9_\-]*$")
_YAML_WORDS = {"y", "n", "yes", "no", "on", "off", "true", "false", "null", "~"}


def _scalar(v: Any) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        if not math.isfinite(v):
            raise error(None, f"a model value must be finite, got {v!r}")
        text = repr(v)
        # YAML 1.1 readers want a dot and a signed exponent: 1e-06 -> 1.0e-06.
        if "e" in text and "." not in text:
            mant, exp = text.split("e")
            text = f"{mant}.0e{exp}"
        return text
    if isinstance(v, str):
        return v if _PLAIN.match(v) and v.lower() not in _YAML_WORDS else json.dumps(v)
    if v is None:
        return "null"
    raise TypeError(f"{type(v).__name__} is not a model value")


def _flow(v: Any) -> str:
    if isinstance(v, Mapping):
        return "{" + ", ".join(f"{_scalar(k)}: {_flow(x)}" for k, x in v.items()) + "}"
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(_flow(x) for x in v) + "]"
    return _scalar(v)


def model_text(model: Mapping[str, Any], header: str | None = None) -> str:
    """The model dict as YAML text: top-level sections in block style, one line per point,
    body, pair, coordinate...; floats at full precision (``repr``). ``header`` (optional) is
    written first as ``#`` comment lines. ``yaml.safe_load`` gives the dict back."""
    lines = [f"# {h}".rstrip() for h in (header or "").splitlines()]
    for key, value in model.items():
        if isinstance(value, Mapping) and value:
            lines.append(f"{key}:")
            for k, v in value.items():
                lines.append(f"  {_scalar(k)}: {_flow(v)}")
        elif isinstance(value, list) and value and all(isinstance(x, Mapping) for x in value):
            lines.append(f"{key}:")
            lines += [f"  - {_flow(x)}" for x in value]
        else:
            lines.append(f"{key}: {_flow(value)}")
    return "\n".join(lines) + "\n"
