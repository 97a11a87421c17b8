"""Plots of the stiffness reports (:mod:`planardyn.stiffness`): a map of the weakest stiffness
or the first natural frequency over the workspace, and compliance ellipses along a path.
Each takes ``ax=`` (default a new figure's) and returns the artists; nothing is shown."""

from __future__ import annotations

from typing import Any

import numpy as np

from .stiffness import PathStiffness, StiffnessMap

__all__ = ["plot_ellipses", "plot_stiffness_map"]


def _axes(ax: Any) -> Any:
    if ax is not None:
        return ax
    from matplotlib.figure import Figure

    return Figure(figsize=(6, 5)).add_subplot()


def plot_stiffness_map(smap: StiffnessMap, ax: Any = None, what: str = "weakest") -> list[Any]:
    """Filled contours of ``what``: ``'weakest'`` stiffness (N/m) or ``'first_frequency'`` (Hz)."""
    if what not in ("weakest", "first_frequency"):
        raise ValueError(f"what: 'weakest' or 'first_frequency', got {what!r}")
    ax = _axes(ax)
    values = getattr(smap, what)
    cs = ax.contourf(smap.x, smap.y, values, levels=20)
    bar = ax.figure.colorbar(cs, ax=ax)
    bar.set_label("weakest stiffness (N/m)" if what == "weakest" else "first natural frequency (Hz)")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_aspect("equal")
    return [cs, bar]


def plot_ellipses(path: PathStiffness, ax: Any = None, force: float | None = None) -> list[Any]:
    """The translational compliance ellipses along a path: the displacement under a force of
    ``force`` N in every direction (default: the largest semi-axis drawn a tenth of the path's
    extent), centred on the point."""
    from matplotlib.patches import Ellipse

    ax = _axes(ax)
    if force is None:
        extent = float(np.ptp(path.position, axis=0).max()) or 1.0
        force = 0.1 * extent / float(path.ellipses.max())
    artists: list[Any] = [ax.plot(path.position[:, 0], path.position[:, 1], "k-", lw=0.8)[0]]
    for p, axes, vectors in zip(path.position, path.ellipses, path.axes):
        angle = np.degrees(np.arctan2(vectors[1, 1], vectors[0, 1]))
        e = Ellipse((float(p[0]), float(p[1])), 2 * force * axes[1], 2 * force * axes[0], angle=float(angle),
                    fill=False, color="C0")
        ax.add_patch(e)
        artists.append(e)
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_aspect("equal")
    ax.set_title(f"compliance ellipses: displacement under {force:.3g} N")
    return artists
