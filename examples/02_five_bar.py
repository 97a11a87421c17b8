"""A driven 5R parallel robot (examples/models/five-bar.yaml).

Simulates it under the model's motor torques, then runs the inverse dynamics along the
computed trajectory (all rows at once) to recover the motor torques, and prints the joint
reactions at the end. Saves coordinates, torques and the robot to out/02_five_bar.png.
"""

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
import planardyn as pdy
from planardyn.plot import draw_mechanism, plot_coordinates, plot_efforts

ROOT = Path(__file__).resolve().parents[1]
OUT = ROOT / "out"

mech = pdy.load(ROOT / "examples" / "models" / "five-bar.yaml")
print(mech)
res = mech.simulate()
print(res)
assert res.success, res.message

# Inverse dynamics gives the efforts of the drives; the model's springs and dampers on the
# motor pairs act as well, so compare with the drive efforts the run applied.
tau = mech.inverse_dynamics(res.q, res.qd, res.qdd)
print(f"inverse dynamics vs applied motor torques: largest difference {np.abs(tau - res.tau).max():.2e} N m")

R = mech.reactions(res.q[-1], res.qd[-1], t=res.t[-1])
for name, (fx, fy, _) in zip(mech.pair_names, R):
    print(f"  reaction at {name:>9}: F = ({fx:8.3f}, {fy:8.3f}) N")
print(f"smallest singularity measure along the run: {res.sigma.min():.3f} (0 = singular)")

fig = plt.figure(figsize=(11, 7))
plot_coordinates(res, ax=fig.add_subplot(2, 2, 1))
plot_efforts(res, ax=fig.add_subplot(2, 2, 3))
ax = fig.add_subplot(1, 2, 2)
draw_mechanism(mech, res.x[0], ax=ax, color="0.6", labels=False)
draw_mechanism(mech, res.x[-1], ax=ax)
ax.set_title(f"t = 0 (grey) and t = {res.t[-1]:.2g} s")
fig.suptitle(mech.name)
fig.tight_layout()
OUT.mkdir(exist_ok=True)
fig.savefig(OUT / "02_five_bar.png", dpi=100)
print(f"wrote {OUT / '02_five_bar.png'}")
