"""The browser app: one offline HTML file that holds planardyn's engine as WebAssembly, so a
mechanism can be dragged, edited, simulated and plotted in any current browser with no server
and no network (``planardyn app MODEL -o app.html``; the docs page ``app``).

The page is built from ``web/`` and ``crates/planardyn-wasm`` by ``./dev app`` and shipped in
the wheel as ``planardyn/app_build/app.html``; this module only fills its data element with
the model (its text, as written) and, optionally, a run computed in Python in the data format
of the HTML viewer (played without the engine)::

    >>> import planardyn
    >>> from planardyn.app import write_app
    >>> write_app("five-bar.html", planardyn.models.path("five-bar"))
"""

from __future__ import annotations

import json
import os
from importlib import resources
from pathlib import Path
from typing import TYPE_CHECKING, Any

from .mechanism import load
from .viewer import viewer_data

if TYPE_CHECKING:
    from .mechanism import Mechanism
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
    return page.read_text(encoding="utf-8")


def model_payload(path: str | os.PathLike[str]) -> dict[str, str]:
    """A model file as the page takes it: its text as written (comments kept), its format
    from the extension (.json is JSON, anything else YAML) and its name."""
    p = Path(path)
    fmt = "json" if p.suffix.lower() == ".json" else "yaml"
    return {"text": p.read_text(encoding="utf-8"), "format": fmt, "source": p.name}


def app_html(model: dict[str, str] | None = None, run: dict[str, Any] | None = None) -> str:
    """The page with ``model`` (:func:`model_payload`) and ``run`` (:func:`planardyn.viewer.viewer_data`)
    inline. The JSON is escaped so that no ``</script>`` can end its element."""
    data: dict[str, Any] = {}
    if model is not None:
        data["model"] = model
    if run is not None:
        data["run"] = run
    text = json.dumps(data, allow_nan=False).replace("</", "<\\/")
    page = app_template()
    if DATA_ELEMENT not in page:
        raise AppNotBuiltError(f"planardyn/{APP_FILE} has no data element: rebuild it with ./dev app")
    return page.replace(DATA_ELEMENT, DATA_ELEMENT.replace("{}", text), 1)


def write_app(
    path: str | os.PathLike[str],
    model: str | os.PathLike[str],
    result: SimulationResult | None = None,
    mechanism: Mechanism | None = None,
) -> Path:
    """Write the app for the model file ``model`` to ``path`` (.html); with ``result`` (a run of
    that model), the run too, ready to play. The model is loaded first, so a model that does
    not build raises here (:class:`~planardyn.ModelError`) rather than in the page.
    Returns the path written."""
    mech = mechanism if mechanism is not None else load(model)
    run = None if result is None else viewer_data(mech, result)
    out = Path(path)
    out.write_text(app_html(model_payload(model), run), encoding="utf-8")
    return out
