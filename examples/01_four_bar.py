"""A four-bar released from rest under gravity (examples/models/four-bar-gravity.yaml).

Simulates the passive crank-rocker for the model's 10 s, checks that its total energy stays
at the value the model file states (13.770736975732 J: no drive, no damping), and saves a
figure with the crank angle, the energies and the mechanism at a few instants to
out/01_four_bar.png.
"""

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
import planardyn as pdy
from planardyn.plot import draw_mechanism, plot_coordinates, plot_energy

ROOT = Path(__file__).resolve().parents[1]
OUT = ROOT / "out"

mech = pdy.load(ROOT / "examples" / "models" / "four-bar-gravity.yaml")
print(mech)
res = mech.simulate()
print(res)

total = res.energy.total
print(f"total energy {total[0]:.12f} J at t = 0, largest change {np.abs(total - total[0]).max():.2e} J")
print(f"crank angle between {np.degrees(res.q[:, 0].min()):.1f} and {np.degrees(res.q[:, 0].max()):.1f} deg")
assert res.success, res.message
assert abs(total[0] - 13.770736975732) < 1e-9, total[0]

fig = plt.figure(figsize=(11, 7))
plot_coordinates(res, ax=fig.add_subplot(2, 2, 1))
plot_energy(res, ax=fig.add_subplot(2, 2, 2))
ax = fig.add_subplot(2, 1, 2)
for k in np.linspace(0, len(res.t) - 1, 5).round().astype(int):
    draw_mechanism(mech, res.x[k], ax=ax, labels=False, alpha=0.3 + 0.7 * k / (len(res.t) - 1))
ax.set_title("the mechanism at t = 0, 2.5, 5, 7.5, 10 s (darker: later)")
fig.suptitle(mech.name)
fig.tight_layout()
OUT.mkdir(exist_ok=True)
fig.savefig(OUT / "01_four_bar.png", dpi=100)
print(f"wrote {OUT / '01_four_bar.png'}")
