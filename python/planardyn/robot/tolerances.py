"""The tolerances of the robot tools, in one place, each with its numerical reason.

Lengths are in m, or relative to the model's size L (``Mechanism.scale``) where that is said;
singularity measures are dimensionless (smallest scaled singular value, 0 at the singularity).
"""

from __future__ import annotations

# The core owns the motion tolerances (``planardyn::kinematics::effector::SINGULAR_TOL``: a
# motion is refused where a singularity measure falls below it, where rates or efforts grow as
# 1/sigma; ``planardyn::dynamics::task::JUMP_TOL``: a solved q farther than this from its
# predictor, in rad or L, jumped to another working mode).
from .._core import JUMP_TOL, SINGULAR_TOL  # noqa: F401 - re-exported

#: A working mode must reproduce the end-effector position X to this (m): a hundred times the
#: core's inverse-kinematics tolerance (1e-11 L) for a robot of L = 1 m, so a converged solve
#: passes and a solve that went elsewhere does not.
WORKING_TOL = 1e-9

#: Two assembly or working modes are the same when no named point differs by more than this
#: (m): the core's position residual (~1e-12 L) is far below it, and distinct branches of a
#: mechanism of any practical size are far above it.
DEDUP_TOL = 1e-9

#: In a workspace of a 2-input robot, an image of an input-box cell this many times the
#: median image size joins two branches of the position analysis (the core's continuation
#: switched branch between two samples) and is not filled: on one branch the images of
#: neighbouring cells are of comparable size, so one 20 times the median spans a jump.
QUAD_JUMP = 20.0

#: Cell centres within this fraction of a cell of a quadrilateral's edge count as inside it,
#: so that round-off does not open a seam between two quadrilaterals that share an edge.
EDGE_TOL = 1e-9
