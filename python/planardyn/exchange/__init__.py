"""Exchange with the robot-description formats: MJCF (MuJoCo), URDF (ROS) and SDF (Gazebo).

    from planardyn.exchange import to_mjcf, to_urdf, to_sdf, from_mjcf, from_urdf

    xml = to_mjcf(pdn.load_example("four-bar-gravity"))      # a string of MJCF
    model = from_mjcf(xml)                                     # a model dict: pdn.from_dict(model)

How each pair, load and actuator maps, the loop conventions and what cannot map:
docs/exchange.md.
"""

from __future__ import annotations

from .mjcf import to_mjcf
from .tree import ExchangeError

__all__ = ["ExchangeError", "to_mjcf"]
