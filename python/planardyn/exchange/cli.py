"""``planardyn export`` and ``planardyn import``: the exchange formats from the command line.

    planardyn export MODEL -o out.xml|.mjcf|.urdf|.sdf [--timestep DT]
    planardyn import FILE.xml|.mjcf|.urdf -o model.yaml|.json [--coordinates J1,J2]

``register(subparsers)`` adds both commands to the planardyn parser; each sets ``run``.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np

from ..mechanism import from_dict, load
from ..results_format import writing
from .mjcf import TIMESTEP, from_mjcf, to_mjcf
from .sdf import to_sdf
from .tree import ExchangeError
from .urdf import from_urdf, to_urdf

WRITERS = {".xml": "mjcf", ".mjcf": "mjcf", ".urdf": "urdf", ".sdf": "sdf"}
READERS = {".xml": "mjcf", ".mjcf": "mjcf", ".urdf": "urdf"}


def register(sub: argparse._SubParsersAction) -> None:
    """Add ``export`` and ``import`` to the planardyn command's subparsers."""
    formatter = argparse.RawDescriptionHelpFormatter
    e = sub.add_parser("export", help="write a model as MJCF (MuJoCo), URDF (ROS) or SDF (Gazebo)",
                       description="Write a model for MuJoCo (.xml, .mjcf), ROS (.urdf) or Gazebo (.sdf), by the\n"
                                   "extension of -o. What the format cannot carry is listed in a comment at the top\n"
                                   "of the file; `planardyn docs exchange` has the mapping.",
                       epilog="examples:\n  planardyn export four-bar-gravity -o four-bar.xml\n"
                              "  planardyn export five-bar -o five-bar.urdf", formatter_class=formatter)
    e.add_argument("model", type=Path, help="model file, or a shipped model by name (five-bar)")
    e.add_argument("-o", "--output", type=Path, required=True, help="FILE.xml, FILE.mjcf, FILE.urdf or FILE.sdf")
    e.add_argument("--timestep", type=float, default=TIMESTEP, help=f"MJCF: MuJoCo's step (s), default {TIMESTEP:g}")
    e.set_defaults(run=export_command)
    i = sub.add_parser("import", help="read the planar subset of an MJCF or URDF file into a model file",
                       description="Read an MJCF (.xml, .mjcf) or URDF (.urdf) file's planar subset (hinges about z,\n"
                                   "slides in the x-y plane, closing connect equalities or <gazebo> joints) and write\n"
                                   "a planardyn model file (.yaml or .json).",
                       epilog="examples:\n  planardyn import four-bar.xml -o four-bar.yaml\n"
                              "  planardyn import linkage.urdf -o linkage.json --coordinates crank", formatter_class=formatter)
    i.add_argument("file", type=Path, help="FILE.xml, FILE.mjcf or FILE.urdf")
    i.add_argument("-o", "--output", type=Path, required=True, help="model file to write: .yaml or .json")
    i.add_argument("--coordinates", help="URDF: comma-separated joints to take as the coordinates")
    i.set_defaults(run=import_command)


def export_command(args: argparse.Namespace) -> int:
    fmt = WRITERS.get(args.output.suffix.lower())
    if fmt is None:
        raise ExchangeError(f"{args.output}: the extension must be one of {', '.join(WRITERS)}")
    mech = load(args.model)
    xml = to_mjcf(mech, timestep=args.timestep) if fmt == "mjcf" else to_urdf(mech) if fmt == "urdf" else to_sdf(mech)
    with writing(args.output):  # a failure named by the path given, its cause in words
        args.output.write_text(xml, encoding="utf-8")
    print(f"wrote {args.output} ({fmt.upper()}, {mech.n_bodies} bodies)")
    return 0


def import_command(args: argparse.Namespace) -> int:
    fmt = READERS.get(args.file.suffix.lower())
    if fmt is None:
        raise ExchangeError(f"{args.file}: the extension must be one of {', '.join(READERS)}")
    text = args.file.read_text(encoding="utf-8")
    coords = args.coordinates.split(",") if args.coordinates else None
    model = from_mjcf(text, str(args.file)) if fmt == "mjcf" else from_urdf(text, str(args.file), coords)
    mech = from_dict(model, str(args.file))  # validates before writing
    if args.output.suffix.lower() not in (".json", ".yaml", ".yml"):
        raise ExchangeError(f"{args.output}: write a .yaml or .json model file")
    # JSON is YAML too (YAML 1.2 is a superset): one writer for both, full precision, no PyYAML needed.
    with writing(args.output):
        args.output.write_text(json.dumps(_plain(model), indent=2) + "\n", encoding="utf-8")
    print(f"wrote {args.output} ({mech.n_bodies} bodies, {len(mech.pair_names)} pairs, coordinates "
          f"{', '.join(mech.coordinate_names)})")
    return 0


def _plain(value: object) -> object:
    """Numbers as Python floats for YAML."""
    if isinstance(value, dict):
        return {k: _plain(v) for k, v in value.items()}
    if isinstance(value, list):
        return [_plain(v) for v in value]
    return float(value) if isinstance(value, np.floating) else value
