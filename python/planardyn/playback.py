"""How fast a result plays back, shared by the animations and the browser app's runs (planardyn.replay)."""

from __future__ import annotations

import numpy as np

#: Shortest and longest playback (s) of the default speed: a short run is not over before it
#: is seen, a long one does not keep the user waiting.
MIN_PLAYBACK, MAX_PLAYBACK = 3.0, 10.0


def auto_speed(t: np.ndarray) -> float:
    """Playback speed (simulated s per s) that shows the run in 3 to 10 s: real time when
    it lasts that long, slow motion for a shorter run, faster for a longer one."""
    span = float(t[-1] - t[0]) if len(t) > 1 else 0.0
    if span <= 0:
        return 1.0
    return span / min(max(span, MIN_PLAYBACK), MAX_PLAYBACK)
