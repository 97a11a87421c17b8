"""Exchange with the robot-description formats: MJCF (MuJoCo), URDF (ROS) and SDF (Gazebo).

    from planardyn.exchange import to_mjcf, to_urdf, to_sdf, from_mjcf, from_urdf

    xml = to_mjcf(pdn.load_example("four-bar-gravity"))      # a string of MJCF
    model = from_mjcf(xml)                                     # a model dict: pdn.from_dict(model)

How each pair, load and actuator maps, the loop conventions and what cannot map:
docs/exchange.md.
"""

from __future__ import annotations

from .mjcf import from_mjcf, to_mjcf
from .sdf import to_sdf
from .tree import ExchangeError
from .urdf import from_urdf, to_urdf

__all__ = ["ExchangeError", "from_mjcf", "from_urdf", "to_mjcf", "to_sdf", "to_urdf"]
