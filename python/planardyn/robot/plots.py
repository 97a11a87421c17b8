"""Figures of the robot tools, one function per object: :func:`plot_motion` (a
:class:`TaskMotion`), :func:`plot_sizing` (a :class:`SizingReport`),
:func:`plot_singularity_map` (a :class:`TaskGrid`), :func:`plot_workspace` (a
:class:`Workspace`), :func:`plot_capability` (a :class:`CapabilityMap`) and
:func:`plot_modes` (a list of :class:`Mode`). Each takes ``fig=`` or ``ax=`` (new ones only
when None) and returns the artists; nothing changes rcParams or calls ``plt.show()``.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

from ..plot import axis_label, draw_mechanism
from .tolerances import SINGULAR_TOL

if TYPE_CHECKING:
    from .capability import CapabilityMap
    from .maps import TaskGrid, Workspace
    from .modes import Mode
    from .motion import TaskMotion
    from .sizing import SizingReport


def _figure(fig: Any, size: tuple[float, float]) -> Any:
    if fig is not None:
        return fig
    from matplotlib.figure import Figure

    return Figure(figsize=size)


def _draw_robot(ax: Any, mech: Any, q: Any = None) -> list[Any]:
    x = mech.x0 if q is None else mech.kinematics(q)["x"]
    return draw_mechanism(mech, x, ax=ax, labels=False, alpha=0.5)


def _sigma_axes(ax: Any, t: Any, s_I: Any, s_II: Any, tol: float) -> list[Any]:
    out = ax.semilogy(t, s_I, label="type I (sigma_I, of J)") + ax.semilogy(t, s_II, label="type II (sigma_II)")
    out.append(ax.axhline(tol, color="r", linestyle="--", linewidth=0.8, label=f"refused below {tol:g}"))
    ax.set_xlabel("t (s)")
    ax.set_ylabel("singularity measure (-)")
    ax.legend(loc="best", fontsize="small")
    ax.grid(True, which="both", alpha=0.3)
    return out


def plot_motion(motion: TaskMotion, fig: Any = None) -> list[Any]:
    """Path with the robot at its start, inputs q(t), efforts tau(t), singularity measures,
    on one figure (2 x 2)."""
    fig = _figure(fig, (11, 7))
    ax = fig.subplots(2, 2)
    mech = motion.mech
    out = _draw_robot(ax[0, 0], mech, motion.q[0])
    out += ax[0, 0].plot(motion.X[:, 0], motion.X[:, 1], "k-", linewidth=1.5, label=f"path of {motion.effector.point}")
    ax[0, 0].set_xlabel("x (m)")
    ax[0, 0].set_ylabel("y (m)")
    ax[0, 0].legend(loc="best", fontsize="small")
    for k, name in enumerate(mech.coordinate_names):
        out += ax[0, 1].plot(motion.t, motion.q[:, k], label=name)
        out += ax[1, 0].plot(motion.t, motion.tau[:, k], label=f"tau_{name}")
    names = mech.coordinate_names
    ax[0, 1].set_ylabel(axis_label("inputs q", names, mech.coordinate_units))
    ax[1, 0].set_ylabel(axis_label("drive efforts", [f"tau_{n}" for n in names], mech.effort_units))
    for a in (ax[0, 1], ax[1, 0]):
        a.set_xlabel("t (s)")
        a.legend(loc="best", fontsize="small")
        a.grid(True, alpha=0.3)
    out += _sigma_axes(ax[1, 1], motion.t, motion.sigma_I, motion.sigma_II, SINGULAR_TOL)
    fig.suptitle(f"{mech.name}: {motion.label}")
    fig.tight_layout()
    return out


def plot_sizing(report: SizingReport, fig: Any = None) -> list[Any]:
    """Efforts against time; operating points (speed, effort) with the envelope; power;
    singularity measures, on one figure (2 x 2)."""
    fig = _figure(fig, (11, 7))
    ax = fig.subplots(2, 2)
    m = report.motion
    out: list[Any] = []
    for k, d in enumerate(report.drives):
        (line,) = ax[0, 0].plot(m.t, m.tau[:, k], label=f"{d.name} (RMS {d.rms_effort:.3g} {d.effort_unit})")
        c = line.get_color()
        out.append(line)
        out += ax[0, 0].plot(m.t, np.full_like(m.t, d.rms_effort), "--", color=c, linewidth=0.8)
        if d.motor is None:
            out += ax[0, 1].plot(np.abs(m.qd[:, k]), np.abs(m.tau[:, k]), ".", color=c, markersize=2, alpha=0.5)
            out += ax[0, 1].step(d.envelope_speed, d.envelope_effort, where="post", color=c, label=f"{d.name} envelope")
        else:
            mo = d.motor
            out += ax[0, 1].plot(np.abs(mo.speed), np.abs(mo.torque), ".", color=c, markersize=2, alpha=0.5)
            out += ax[0, 1].plot(mo.envelope_speed, mo.envelope_torque, color=c,
                                 label=f"{d.name} motor {mo.name} ({'pass' if mo.passed else 'FAIL'})")
        out += ax[1, 0].plot(m.t, m.tau[:, k] * m.qd[:, k], color=c, label=f"{d.name} (peak {d.peak_power:.3g} W)")
    names = [d.name for d in report.drives]
    ax[0, 0].set(xlabel="t (s)", ylabel=axis_label("effort", names, [d.effort_unit for d in report.drives]),
                 title="efforts (dashed: RMS)")
    motors = any(d.motor is not None for d in report.drives)
    # The motor side where a drive has a motor (N m, rad/s), else the joint side.
    side = [("N m", "rad/s") if d.motor is not None else (d.effort_unit, d.speed_unit) for d in report.drives]
    ax[0, 1].set(xlabel=axis_label("|speed|", names, [v for _, v in side]),
                 ylabel=axis_label("|effort|", names, [e for e, _ in side]),
                 title="torque-speed: motor side and motor envelope" if motors else "torque-speed envelope")
    ax[1, 0].set(xlabel="t (s)", ylabel="power tau qd (W)", title="mechanical power")
    for a in (ax[0, 0], ax[0, 1], ax[1, 0]):
        a.legend(loc="best", fontsize="small")
        a.grid(True, alpha=0.3)
    out += _sigma_axes(ax[1, 1], m.t, m.sigma_I, m.sigma_II, SINGULAR_TOL)
    ax[1, 1].set_title("distance to singularities")
    extra = f", payload {report.payload:g} kg" if report.payload else ""
    fig.suptitle(f"actuator sizing: {m.mech.name}, {m.label}{extra}")
    fig.tight_layout()
    return out


def plot_singularity_map(grid: TaskGrid, fig: Any = None, levels: tuple[float, ...] = (0.02, 0.05)) -> list[Any]:
    """sigma_I and sigma_II maps (log colour), loci as contours at small ``levels``."""
    from matplotlib.colors import LogNorm

    fig = _figure(fig, (11, 5))
    axes = fig.subplots(1, 2, sharey=True)
    out: list[Any] = []
    for ax, name, z, color in ((axes[0], "type I: sigma_I (J)", grid.sigma_I, "r"),
                               (axes[1], "type II: sigma_II", grid.sigma_II, "m")):
        zz = np.ma.masked_invalid(np.clip(z, 1e-4, None))
        mesh = ax.pcolormesh(grid.x, grid.y, zz, shading="nearest", cmap="viridis", norm=LogNorm(1e-3, 1))
        out.append(mesh)
        fig.colorbar(mesh, ax=ax, label="measure (-), 0 = singular")
        if np.isfinite(z).sum() > 4:
            out.append(ax.contour(grid.x, grid.y, np.ma.masked_invalid(z), levels=sorted(levels), colors=color,
                                  linewidths=(1.8, 0.9)[: len(levels)]))
        out.append(ax.contour(grid.x, grid.y, grid.reachable.astype(float), levels=[0.5], colors="k", linewidths=0.8))
        out += _draw_robot(ax, grid.effector.mech)
        ax.set(title=f"{name}; contours at {', '.join(f'{v:g}' for v in levels)}", xlabel="x (m)")
        ax.set_aspect("equal")
    axes[0].set_ylabel("y (m)")
    pose = f", psi = {grid.psi:g} rad" if grid.effector.dim == 3 else ""
    fig.suptitle(f"{grid.effector.mech.name}: singularity measures of {grid.effector.point}{pose} "
                 f"(white: unreachable on this working mode; black: its edge)")
    fig.tight_layout()
    return out


def plot_workspace(ws: Workspace, ax: Any = None) -> list[Any]:
    """Dexterity 1/kappa inside the workspace boundary, the robot drawn on top."""
    if ax is None:
        from matplotlib.figure import Figure

        ax = Figure(figsize=(7, 6)).subplots()
    out: list[Any] = []
    mesh = ax.pcolormesh(ws.x, ws.y, np.ma.masked_invalid(ws.dexterity), shading="nearest", cmap="viridis",
                         vmin=0, vmax=1)
    out.append(mesh)
    ax.figure.colorbar(mesh, ax=ax, label="dexterity 1/kappa(J) (-), 0 = type I singular")
    for k, line in enumerate(ws.boundary()):
        out += ax.plot(line[:, 0], line[:, 1], "k-", linewidth=1.2, label="boundary" if k == 0 else None)
    out += _draw_robot(ax, ws.effector.mech)
    ax.set(xlabel="x (m)", ylabel="y (m)",
           title=f"{ws.effector.mech.name}: workspace of {ws.effector.point}, area {ws.area * 1e4:.1f} cm^2\n({ws.method})")
    ax.set_aspect("equal")
    ax.legend(loc="upper right", fontsize="small")
    return out


def plot_capability(cmap: CapabilityMap, ax: Any = None) -> list[Any]:
    """Guaranteed acceleration (colour), cells where holding still exceeds a limit hatched
    grey, the robot in its drawing."""
    if ax is None:
        from matplotlib.figure import Figure

        ax = Figure(figsize=(7, 6)).subplots()
    out: list[Any] = []
    z = np.ma.masked_invalid(np.where(cmap.accel > 0, cmap.accel, np.nan))
    mesh = ax.pcolormesh(cmap.x, cmap.y, z, shading="nearest", cmap="viridis")
    out.append(mesh)
    ax.figure.colorbar(mesh, ax=ax, label="guaranteed acceleration at rest (m/s^2)")
    zero = np.where(cmap.accel == 0, 1.0, np.nan)
    if np.isfinite(zero).any():
        out.append(ax.pcolormesh(cmap.x, cmap.y, np.ma.masked_invalid(zero), shading="nearest", cmap="Greys",
                                 vmin=0, vmax=2))
    out.append(ax.contour(cmap.x, cmap.y, cmap.grid.reachable.astype(float), levels=[0.5], colors="k",
                          linewidths=0.8))
    out += _draw_robot(ax, cmap.effector.mech)
    lim = ", ".join(f"{t:g}" for t in cmap.tau_max)
    ax.set(xlabel="x (m)", ylabel="y (m)",
           title=f"{cmap.effector.mech.name}: acceleration of {cmap.effector.point} in every direction\n"
                 f"at rest, |tau| <= [{lim}] (grey: holding still exceeds a limit)")
    ax.set_aspect("equal")
    return out




def plot_modes(modes: list[Mode], ax: Any = None, title: str | None = None) -> list[Any]:
    """Every mode's configuration on one axes (one colour each, named in the legend)."""
    if ax is None:
        from matplotlib.figure import Figure

        ax = Figure(figsize=(6, 5)).subplots()
    out: list[Any] = []
    colors = ["C0", "C1", "C2", "C3", "C4", "C5", "C6", "C7"]
    for k, mode in enumerate(modes):
        src = mode._source
        c = colors[k % len(colors)]
        first = True
        for bp in src.body_points:
            names = [n for n, _ in bp]
            idx = [src.point_names.index(n) for n in names]
            p = mode.points[idx]
            if len(p) > 2:
                p = np.vstack([p, p[:1]])
            out += ax.plot(p[:, 0], p[:, 1], "-o", color=c, linewidth=2, markersize=4, alpha=0.8,
                           label=f"{mode.name} (sigma_II {mode.sigma_min:.2f})" if first else None)
            first = False
    ax.set(xlabel="x (m)", ylabel="y (m)")
    if title:
        ax.set_title(title)
    ax.set_aspect("equal")
    ax.grid(True, alpha=0.3)
    ax.legend(loc="best", fontsize="small")
    return out
