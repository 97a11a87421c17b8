"""requirements-lock.txt, the versions `./dev` installs on its Python, against
requirements-dev.txt, the lower bounds: a lock written before a bound was raised, or one
missing a requirement, would install something the bounds refuse or leave a package unpinned.

Expected values: the requirements are those of requirements-dev.txt, read with `packaging`
(pip's own parser); the lock's Python line is the one `./dev lock` writes.
"""

from __future__ import annotations

import re

from conftest import ROOT
from packaging.requirements import Requirement
from packaging.utils import canonicalize_name


def _lines(name: str) -> list[str]:
    text = (ROOT / name).read_text()
    return [line.split("#")[0].strip() for line in text.splitlines() if line.split("#")[0].strip()]


def _pins() -> dict[str, str]:
    pins = {}
    for line in _lines("requirements-lock.txt"):
        name, _, version = line.partition("==")
        assert version, f"requirements-lock.txt: {line!r} is not pinned with =="
        pins[canonicalize_name(name)] = version
    return pins


def _lock_python() -> str:
    found = re.findall(r"^# python (\d+\.\d+)$", (ROOT / "requirements-lock.txt").read_text(), re.M)
    assert len(found) == 1, found
    return found[0]


def test_lock_names_its_python():
    assert re.fullmatch(r"3\.(1[0-9]|[2-9][0-9])", _lock_python())


def test_every_requirement_is_pinned_within_its_bounds():
    pins, python = _pins(), _lock_python()
    checked = 0
    for line in _lines("requirements-dev.txt"):
        req = Requirement(line)
        if req.marker is not None and not req.marker.evaluate({"python_version": python}):
            continue
        name = canonicalize_name(req.name)
        assert name in pins, f"requirements-lock.txt has no version of {req.name}: run ./dev lock"
        assert req.specifier.contains(pins[name], prereleases=True), (
            f"requirements-lock.txt pins {req.name}=={pins[name]}, outside {req.specifier}: run ./dev lock"
        )
        checked += 1
    assert checked > 0
