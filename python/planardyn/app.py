"""The browser app: one offline HTML file that holds planardyn's engine as WebAssembly, so a
mechanism can be dragged, edited, simulated and plotted in any current browser with no server
and no network (``planardyn app MODEL -o app.html``, ``planardyn animate ... -o run.html``;
the docs page ``app``).

The page is built from ``web/`` and ``crates/planardyn-wasm`` by ``./dev app`` and shipped in
the wheel as ``planardyn/app_build/app.html``; this module only fills its data element with
the model (its text) and, optionally, a run computed in Python (:func:`planardyn.replay.run_data`,
played without the engine)::

    >>> import planardyn
    >>> from planardyn.app import write_app
    >>> write_app("five-bar.html", planardyn.models.path("five-bar"))
"""

from __future__ import annotations

import json
import os
from importlib import resources
from pathlib import Path
from typing import Any

from . import models
from .mechanism import Mechanism, load
from .model_text import model_text
from .replay import run_data
from .result import SimulationResult

#: The built page inside the package.
APP_FILE = "app_build/app.html"
#: The page's data element, as web/app.html writes it: filled with the model and the run.
DATA_ELEMENT = '<script type="application/json" id="planardyn-data">{}</script>'


class AppNotBuiltError(FileNotFoundError):
    """This installation has no built app (a source checkout before ``./dev app``)."""


def app_template() -> str:
    """The built page, with its data element empty.

    Raises
    ------
    AppNotBuiltError
        The page was not built: in a checkout of the repository, run ``./dev app``.
    """
    page = resources.files("planardyn").joinpath(APP_FILE)
    if not page.is_file():
        raise AppNotBuiltError(
            f"the browser app is not in this installation (planardyn/{APP_FILE}): in a checkout of the "
            "repository run ./dev app (or ./dev setup) to build it; a planardyn wheel ships it built"
        )
    page_text = page.read_text(encoding="utf-8")
    if DATA_ELEMENT not in page_text:
        raise AppNotBuiltError(f"planardyn/{APP_FILE} has no data element: rebuild it with ./dev app")
    return page_text


def model_payload(path: str | os.PathLike[str]) -> dict[str, str]:
    """A model file as the page takes it: its text as written (comments kept), its format
    from the extension (.json is JSON, anything else YAML) and its name."""
    p = Path(path)
    fmt = "json" if p.suffix.lower() == ".json" else "yaml"
    return {"text": p.read_text(encoding="utf-8"), "format": fmt, "source": p.name}


def mechanism_payload(mech: Mechanism) -> dict[str, str]:
    """A built mechanism as the page takes it: its specification as YAML model text
    (:func:`planardyn.model_text.model_text`; loading it gives the same mechanism back)."""
    header = f"{mech.name}: the model as planardyn built it from {mech.source}"
    return {"text": model_text(mech.to_dict(), header), "format": "yaml", "source": Path(mech.source).name}


def shipped_models() -> dict[str, str]:
    """The text of every shipped model by name (:func:`planardyn.models.names`, the library's
    files left out; about 30 kB), for the page's menu of models to start from."""
    return {name: models.path(name).read_text(encoding="utf-8") for name in models.names() if "/" not in name}


def page_data(
    model: dict[str, str] | None = None, run: dict[str, Any] | None = None, shipped: dict[str, str] | None = None
) -> str:
    """The JSON of the page's data element: ``model`` (:func:`model_payload`), ``run``
    (:func:`planardyn.replay.run_data`) and ``shipped`` (:func:`shipped_models`), every ``<``
    escaped (``\\u003c``, the same string once parsed) so that nothing in it can end the element."""
    data: dict[str, Any] = {}
    if model is not None:
        data["model"] = model
    if run is not None:
        data["run"] = run
    if shipped is not None:
        data["shipped"] = shipped
    return json.dumps(data, separators=(",", ":"), allow_nan=False).replace("<", "\\u003c")


def app_html(model: dict[str, str] | None = None, run: dict[str, Any] | None = None) -> str:
    """The page with ``model``, ``run`` and the shipped models inline (:func:`page_data`)."""
    data = page_data(model, run, shipped_models())
    return app_template().replace(DATA_ELEMENT, DATA_ELEMENT.replace("{}", data), 1)


def payloads(
    model: str | os.PathLike[str] | Mechanism,
    result: SimulationResult | None = None,
    mechanism: Mechanism | None = None,
    **run_kw: Any,
) -> tuple[dict[str, str], dict[str, Any] | None]:
    """(model, run) for the page: ``model`` a model file (its text as written) or a built
    mechanism; the run of ``result`` (``run_kw`` go to :func:`planardyn.replay.run_data`).
    A model file is loaded first (unless ``mechanism`` is it, built), so a model that does not
    build raises here (:class:`~planardyn.ModelError`) rather than in the page."""
    if isinstance(model, Mechanism):
        mech, payload = model, mechanism_payload(model)
    else:
        mech, payload = (mechanism if mechanism is not None else load(model)), model_payload(model)
    return payload, None if result is None else run_data(mech, result, **run_kw)


def write_app(
    path: str | os.PathLike[str],
    model: str | os.PathLike[str] | Mechanism,
    result: SimulationResult | None = None,
    mechanism: Mechanism | None = None,
    **run_kw: Any,
) -> Path:
    """Write the app for ``model`` (a model file, or a built :class:`~planardyn.Mechanism`) to
    ``path`` (.html); with ``result`` (a run of that model), the run too, ready to play
    (``run_kw``: ``channels``, ``traces``, ``max_frames``, ``title`` of
    :func:`planardyn.replay.run_data`). Returns the path written."""
    out = Path(path)
    out.write_text(app_html(*payloads(model, result, mechanism, **run_kw)), encoding="utf-8")
    return out
