"""Maps over the workspace: singularity measures of both kinds on a grid of end-effector
positions (inverse kinematics by continuation from cell to cell), and the reachable
workspace of an end-effector point with its dexterity (condition number of the scaled J).

Grids are (ny, nx) arrays, row j at y[j], column i at x[i]; NaN marks an unreachable cell.
"""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass
from typing import cast

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .._core import AssemblyError, SingularityError
from ..arguments import count, error
from .effector import EffectorState, EndEffector
from .tolerances import EDGE_TOL, JUMP_TOL, QUAD_JUMP, SINGULAR_TOL

FloatArray = NDArray[np.float64]

# Newton attempts at one cell (from different solved neighbours) before it is unreachable.
MAX_ATTEMPTS = 4


@dataclass(repr=False)
class TaskGrid:
    """Measures on a grid of end-effector positions (orientation psi fixed for a pose).

    ``x`` (nx,), ``y`` (ny,) m; ``sigma_I``, ``sigma_II``, ``condition`` (ny, nx), NaN where
    unreachable on the working mode; ``q`` (ny, nx, m) the inputs there (rad or m).
    """

    effector: EndEffector
    x: FloatArray
    y: FloatArray
    psi: float
    q: FloatArray
    sigma_I: FloatArray
    sigma_II: FloatArray
    condition: FloatArray

    @property
    def reachable(self) -> NDArray[np.bool_]:
        return np.isfinite(self.sigma_I)

    def __repr__(self) -> str:
        return (f"TaskGrid({self.effector.point} of {self.effector.mech.name}: {len(self.y)} x {len(self.x)} cells, "
                f"x {self.x[0]:.4g} .. {self.x[-1]:.4g} m, y {self.y[0]:.4g} .. {self.y[-1]:.4g} m, "
                f"{int(self.reachable.sum())} reachable)")

    @property
    def area(self) -> float:
        """Area (m^2) of the reachable cells."""
        return float(self.reachable.sum() * np.diff(self.x).mean() * np.diff(self.y).mean())


def grid_size(n: int | tuple[int, int]) -> tuple[int, int]:
    """(nx, ny): ``n`` points per side, or the (nx, ny) given, each an integer >= 1."""
    sides = tuple(n) if np.ndim(n) == 1 else (n, n)  # type: ignore[arg-type]  # ndim 1: iterable
    if len(sides) != 2:
        raise error("n", f"n = {n!r} must be one integer or two, (nx, ny)")
    return count("n", sides[0]), count("n", sides[1])


def _neighbours(j: int, i: int, ny: int, nx: int) -> list[tuple[int, int]]:
    return [(a, b) for a, b in ((j + 1, i), (j - 1, i), (j, i + 1), (j, i - 1)) if 0 <= a < ny and 0 <= b < nx]


def _in_ranges(q: FloatArray, ranges: FloatArray | None) -> bool:
    return ranges is None or bool(np.all((q >= ranges[:, 0]) & (q <= ranges[:, 1])))


def flood(ee: EndEffector, x: FloatArray, y: FloatArray, psi: float = 0.0, q_start: ArrayLike | None = None,
          ranges: FloatArray | None = None, singular_tol: float = SINGULAR_TOL) -> TaskGrid:
    """Inverse kinematics on every cell reachable from the start by continuation through
    neighbouring cells (breadth first), on the start's working mode. A cell is solved from a
    solved neighbour with the predictor q + J^-1 dX; a solution that departs from it by more
    than JUMP_TOL, leaves the input ``ranges`` ((m, 2)), or is within ``singular_tol`` of a
    singularity is not continued from (the loci bound the region)."""
    nx, ny, m = len(x), len(y), ee.mech.dof
    shape = (ny, nx)
    q = np.full((*shape, m), np.nan)
    sI, sII, cond = np.full(shape, np.nan), np.full(shape, np.nan), np.full(shape, np.nan)
    attempts = np.zeros(shape, dtype=int)
    target = (lambda j, i: np.array([x[i], y[j]])) if ee.dim == 2 else (lambda j, i: np.array([x[i], y[j], psi]))

    st0 = ee.state(ee.mech.drawn_q if q_start is None else q_start)
    j0, i0 = int(np.argmin(np.abs(y - st0.X[1]))), int(np.argmin(np.abs(x - st0.X[0])))
    try:
        st = ee.inverse(target(j0, i0), st0.q, x_start=st0.kin["x"])
    except (AssemblyError, SingularityError) as exc:
        raise AssemblyError(f"the grid cell nearest the start, {target(j0, i0)}, cannot be reached: {exc}") from exc
    states: dict[tuple[int, int], EffectorState] = {}

    def keep(j: int, i: int, s: EffectorState) -> None:
        q[j, i], sI[j, i], sII[j, i], cond[j, i] = s.q, s.sigma_I, s.sigma_II, ee.condition(s.J)
        if min(s.sigma_I, s.sigma_II) >= singular_tol and _in_ranges(s.q, ranges):
            states[(j, i)] = s
            queue.append((j, i))

    queue: deque[tuple[int, int]] = deque()
    if _in_ranges(st.q, ranges):
        keep(j0, i0, st)
    while queue:
        j, i = queue.popleft()
        s = states[(j, i)]
        for a, b in _neighbours(j, i, ny, nx):
            if np.isfinite(sI[a, b]) or attempts[a, b] >= MAX_ATTEMPTS:
                continue
            attempts[a, b] += 1
            X = target(a, b)
            pred = s.q + np.linalg.solve(s.J, X - s.X)
            try:
                new = ee.solve(X, pred, x_start=s.kin["x"])
            except (AssemblyError, SingularityError, np.linalg.LinAlgError):
                continue
            if np.max(np.abs(new.q - pred) / ee._input_scale) > JUMP_TOL or not _in_ranges(new.q, ranges):
                continue
            keep(a, b, new)
    return TaskGrid(ee, x, y, float(psi), q, sI, sII, cond)


def singularity_map(ee: EndEffector, xlim: tuple[float, float], ylim: tuple[float, float], n: int | tuple[int, int] = 60,
                    psi: float = 0.0, q_start: ArrayLike | None = None) -> TaskGrid:
    """Type I and type II measures over a grid of end-effector positions.

    Parameters
    ----------
    ee : EndEffector
    xlim, ylim : (2,) m
        The region.
    n : int or (nx, ny)
        Grid points per side.
    psi : float
        Orientation (rad from the drawn one) for a pose (m = 3).
    q_start : (m,), optional
        A configuration on the working mode to map (default the drawing).
    """
    nx, ny = grid_size(n)
    return flood(ee, np.linspace(*xlim, nx), np.linspace(*ylim, ny), psi, q_start)


@dataclass(repr=False)
class Workspace:
    """Reachable positions of an end-effector point.

    ``points`` (K, 2) m: the positions found; ``x`` (nx,), ``y`` (ny,) cell centres (m);
    ``occupied`` (ny, nx) bool; ``dexterity`` (ny, nx): the best (largest) inverse condition
    number 1/kappa of the scaled J found in each cell (1 isotropic, 0 singular; NaN outside);
    ``area`` (m^2); ``method``: how it was found.
    """

    effector: EndEffector
    points: FloatArray
    x: FloatArray
    y: FloatArray
    occupied: NDArray[np.bool_]
    dexterity: FloatArray
    area: float
    method: str

    def __repr__(self) -> str:
        return (f"Workspace({self.effector.point} of {self.effector.mech.name}: area {self.area:.4g} m^2, "
                f"{len(self.points)} positions, {len(self.y)} x {len(self.x)} cells; {self.method})")

    def boundary(self) -> list[FloatArray]:
        """The boundary as closed polylines ((K, 2) m each): the occupancy's 0.5 contour."""
        import contourpy

        z = np.pad(self.occupied.astype(float), 1)
        dx, dy = self.x[1] - self.x[0], self.y[1] - self.y[0]
        xs = np.concatenate([[self.x[0] - dx], self.x, [self.x[-1] + dx]])
        ys = np.concatenate([[self.y[0] - dy], self.y, [self.y[-1] + dy]])
        # LineType.Separate: one (K, 2) array per polyline.
        lines = contourpy.contour_generator(xs, ys, z, line_type=contourpy.LineType.Separate).lines(0.5)
        return cast(list[FloatArray], lines)


def _grid_for(points: FloatArray, cells: int, pad: float) -> tuple[FloatArray, FloatArray]:
    lo, hi = points.min(axis=0) - pad, points.max(axis=0) + pad
    h = float(np.max(hi - lo)) / cells
    nx, ny = np.ceil((hi - lo) / h).astype(int) + 1
    return lo[0] + h * np.arange(nx), lo[1] + h * np.arange(ny)


def _fill_quads(x: FloatArray, y: FloatArray, P: FloatArray, d: FloatArray) -> tuple[NDArray[np.bool_], FloatArray]:
    """Occupancy and dexterity of the cells covered by the images of the input-box cells.

    P (n1, n2, 2) positions at the box samples (NaN where unassemblable), d (n1, n2) their
    dexterity. Each box cell whose four corners assemble maps to (about) the quadrilateral of
    their images: its cells are occupied, with the corners' mean dexterity (the best of all
    quadrilaterals covering a cell is kept). A quadrilateral much larger than the typical one
    joins two branches of the core's position analysis and is skipped.
    """
    from matplotlib.path import Path

    quads = np.stack([P[:-1, :-1], P[1:, :-1], P[1:, 1:], P[:-1, 1:]], axis=2).reshape(-1, 4, 2)
    dq = np.stack([d[:-1, :-1], d[1:, :-1], d[1:, 1:], d[:-1, 1:]], axis=2).reshape(-1, 4).mean(axis=1)
    ok = np.all(np.isfinite(quads), axis=(1, 2))
    quads, dq = quads[ok], dq[ok]
    size = np.ptp(quads, axis=1).max(axis=1)
    keep = size <= QUAD_JUMP * max(np.median(size), x[1] - x[0])
    occ = np.zeros((len(y), len(x)), dtype=bool)
    dex = np.full(occ.shape, np.nan)
    h, x0, y0 = x[1] - x[0], x[0], y[0]
    for quad, dv in zip(quads[keep], dq[keep]):
        i0, j0 = np.floor((quad.min(axis=0) - [x0, y0]) / h).astype(int)
        i1, j1 = np.ceil((quad.max(axis=0) - [x0, y0]) / h).astype(int) + 1
        xs, ys = np.meshgrid(x[i0:i1], y[j0:j1])
        inside = Path(quad).contains_points(np.column_stack([xs.ravel(), ys.ravel()]), radius=EDGE_TOL * h)
        inside = inside.reshape(xs.shape)
        # The corners' own cells too (a quadrilateral thinner than a cell covers no centre).
        occ[j0:j1, i0:i1] |= inside
        sub = dex[j0:j1, i0:i1]
        sub[inside] = np.fmax(sub[inside], dv)
    ix = np.clip(np.round((quads[keep].reshape(-1, 2)[:, 0] - x0) / h).astype(int), 0, len(x) - 1)
    iy = np.clip(np.round((quads[keep].reshape(-1, 2)[:, 1] - y0) / h).astype(int), 0, len(y) - 1)
    occ[iy, ix] = True
    np.fmax.at(dex, (iy, ix), np.repeat(dq[keep], 4))
    return occ, dex


def workspace(ee: EndEffector, ranges: ArrayLike | None = None, n: int = 80, cells: int = 120,
              psi: float = 0.0) -> Workspace:
    """The reachable workspace of the end-effector point for inputs within ``ranges``.

    m = 2: the input box is sampled (n per input) and each sample assembled (the core's
    position analysis, from the drawing); each box cell whose corners assemble covers the
    quadrilateral of their images on an occupancy grid of about ``cells`` cells per side (so
    coarse sampling leaves no holes), whose area is the workspace's. m = 3: the
    constant-orientation workspace (psi, rad from the drawing) by continuation over a grid of
    ``cells`` per side (:func:`flood`), keeping the cells whose inputs lie within ``ranges``.

    Parameters
    ----------
    ranges : (m, 2) array_like, optional
        [low, high] per input (rad or m); default the drawn value +- pi for angles,
        +- L for displacements.
    """
    mech = ee.mech
    q0 = mech.drawn_q
    if ranges is None:
        half = np.array([np.pi if k == "angle" else mech.scale for k in mech.coordinate_kinds])
        ranges = np.column_stack([q0 - half, q0 + half])
    ranges = np.asarray(ranges, dtype=float)
    if ranges.shape != (mech.dof, 2) or np.any(ranges[:, 1] <= ranges[:, 0]):
        raise error("ranges", f"ranges must be (m, 2) = ({mech.dof}, 2) with low < high, got {ranges.tolist()}")
    if ee.dim == 3:
        return _workspace_pose(ee, ranges, cells, psi)
    a1, a2 = (np.linspace(lo, hi, n) for lo, hi in ranges)
    P = np.full((n, n, 2), np.nan)
    d = np.full((n, n), np.nan)
    for i, qa in enumerate(a1):
        for j, qb in enumerate(a2):
            try:
                s = ee.state([qa, qb])
            except (AssemblyError, SingularityError):
                continue
            P[i, j], d[i, j] = s.X, 1.0 / ee.condition(s.J)
    found = np.isfinite(P[..., 0])
    if not found.any():
        raise AssemblyError("no sample of the input box can be assembled")
    points = P[found]
    x, y = _grid_for(points, cells, pad=0.02 * mech.scale)
    occ, dex = _fill_quads(x, y, P, d)
    h = x[1] - x[0]
    return Workspace(ee, points, x, y, occ, dex, float(occ.sum() * h * h),
                     f"input box {n} x {n} samples, {len(points)} assembled")


def _workspace_pose(ee: EndEffector, ranges: FloatArray, cells: int, psi: float) -> Workspace:
    # Extent: the farthest a point can be from the drawing is bounded by the model's size.
    home = ee.home()
    L = ee.mech.scale
    x = np.linspace(home[0] - L, home[0] + L, cells)
    y = np.linspace(home[1] - L, home[1] + L, cells)
    grid = flood(ee, x, y, psi, ranges=ranges)
    occ = grid.reachable & np.all(np.isfinite(grid.q), axis=-1)
    occ &= np.all((grid.q >= ranges[:, 0]) & (grid.q <= ranges[:, 1]), axis=-1)
    X, Y = np.meshgrid(x, y)
    h = x[1] - x[0]
    dex = np.where(occ, 1.0 / grid.condition, np.nan)
    return Workspace(ee, np.column_stack([X[occ], Y[occ]]), x, y, occ, dex, float(occ.sum() * h * h),
                     f"constant orientation psi = {psi:g} rad, continuation over {cells} x {cells} cells")
