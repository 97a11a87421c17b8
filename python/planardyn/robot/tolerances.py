"""The tolerances of the robot tools, in one place, each with its numerical reason.

Lengths are in m, or relative to the model's size L (``Mechanism.scale``) where that is said;
singularity measures are dimensionless (smallest scaled singular value, 0 at the singularity).
"""

from __future__ import annotations

#: A motion is refused where either singularity measure falls below this: there the input
#: rates (type I) or the drive efforts (type II) grow as 1/sigma, i.e. about 1000 times their
#: values in a well-conditioned pose.
SINGULAR_TOL = 1e-3

#: Between the samples of a path, a local minimum of a measure below this level (50 times
#: SINGULAR_TOL) is refined by golden section in t: a singularity crossed between two samples
#: shows at the samples only as such a minimum, and one above this level could hide a crossing
#: only if the measure changed by more than 0.05 within half a sample spacing.
REFINE_LEVEL = 0.05

#: Largest departure (rad for angles, L for displacements) of a solved q from its predictor
#: (along a path q + qd h + qdd h^2 / 2, error O(h^3); on a map q + J^-1 dX from a neighbouring
#: cell, error O(dX^2)): both are far smaller at the default spacings, so a larger departure
#: means the solve jumped to another working mode.
JUMP_TOL = 0.05

#: Newton on the task coordinates converges when the scaled residual |X* - X| / L (position
#: rows; psi rows in rad) is below this. The core's own position tolerance is ~1e-12 L, so this
#: is as tight as the positions it is computed from allow.
IK_TOL = 1e-11

#: Two assembly or working modes are the same when no named point differs by more than this
#: (m): the core's position residual (~1e-12 L) is far below it, and distinct branches of a
#: mechanism of any practical size are far above it.
DEDUP_TOL = 1e-9

#: A working mode must reproduce the end-effector position X to this (m): a hundred times
#: IK_TOL for a robot of L = 1 m, so a converged solve passes and a solve that went elsewhere
#: does not.
WORKING_TOL = 1e-9

#: In a workspace of a 2-input robot, an image of an input-box cell this many times the
#: median image size joins two branches of the position analysis (the core's continuation
#: switched branch between two samples) and is not filled: on one branch the images of
#: neighbouring cells are of comparable size, so one 20 times the median spans a jump.
QUAD_JUMP = 20.0

#: Cell centres within this fraction of a cell of a quadrilateral's edge count as inside it,
#: so that round-off does not open a seam between two quadrilaterals that share an edge.
EDGE_TOL = 1e-9
