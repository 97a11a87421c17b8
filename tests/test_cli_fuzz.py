"""Fuzzing the command line: damaged results files and random option values.

Each input is a command (``plot``, ``animate`` to HTML, ``inverse``, ``simulate``) on a
results file damaged at random (truncated at a random offset, bytes flipped, an array, a
column or a metadata key dropped, metadata of another type, random bytes, another .npz) or
with random option values (negative, zero, nan, inf, huge, not a number). Every outcome
must be an exit status 0, 1 or 2 with at most a one-line message: no exception escapes
``cli.main``, none reaches its last-resort handler ("unexpected ..."), and a refused file
is named in the message.

The campaign is seeded: ``PLANARDYN_CLI_FUZZ_N=20000 PLANARDYN_CLI_FUZZ_SEED=7 pytest
tests/test_cli_fuzz.py`` runs a longer one (default 150 inputs, seed 11).
"""

from __future__ import annotations

import io
import itertools
import json
import os
import zipfile
from collections import Counter
from pathlib import Path
from typing import Any

import numpy as np
import planardyn as pd
import pytest
from conftest import MODELS, cli_run

N_INPUTS = int(os.environ.get("PLANARDYN_CLI_FUZZ_N", "150"))
SEED = int(os.environ.get("PLANARDYN_CLI_FUZZ_SEED", "11"))
MODEL = MODELS / "five-bar.yaml"
FORMATS = (".csv", ".npz", ".parquet")

#: Option values: valid, out of range, not finite, not numbers, overflowing.
WORDS = ["0", "-1", "-0", "1", "2", "nan", "inf", "-inf", "1e400", "1e-400", "x", "", "0x10", "9" * 400,
         "1e308", "5e-324", "1e12", "1e13", "20000", "100000", "-1e-9", "3.5", " 2 ", "1_000"]



@pytest.fixture(scope="module")
def originals(tmp_path_factory) -> dict[str, bytes]:
    """A short five-bar run (6 rows) in every results format, as bytes."""
    d = tmp_path_factory.mktemp("valid")
    mech = pd.load(MODEL)
    res = mech.simulate(0.05, output_dt=0.01)
    out = {}
    for ext in FORMATS:
        p = pd.results_io.write_results(res, d / f"run{ext}", mechanism=mech)
        out[ext] = p.read_bytes()
    # A CSV's metadata are in run.csv.json beside it: fuzzed as one text, the metadata's lines
    # first as '# ' lines (write_input puts them back beside the table).
    meta = (d / "run.csv.json").read_text().splitlines()
    out[".csv"] = "".join(f"# {ln}\n" for ln in meta).encode() + out[".csv"]
    return out


def write_input(path: Path, data: bytes) -> None:
    """A results file from (damaged) bytes: a CSV's leading '# ' lines to its metadata file."""
    beside = path.with_name(path.name + ".json")
    beside.unlink(missing_ok=True)
    if path.suffix != ".csv" or not data.startswith(b"# "):
        path.write_bytes(data)
        return
    lines = data.splitlines(keepends=True)
    head = [ln for ln in itertools.takewhile(lambda ln: ln.startswith(b"#"), lines)]
    beside.write_bytes(b"".join(ln[2:] if ln.startswith(b"# ") else ln[1:] for ln in head))
    path.write_bytes(b"".join(lines[len(head):]))


def random_value(rng: np.random.Generator) -> Any:
    kinds = [None, True, -1, 0, 1.5, "x", [], {}, [1, "a"], {"a": 1}, 10**30, float("nan")]
    return kinds[rng.integers(len(kinds))]


def damage_meta(meta: dict[str, Any], rng: np.random.Generator) -> dict[str, Any]:
    """Drop a key or give it a value of another type."""
    meta = dict(meta)
    key = sorted(meta)[rng.integers(len(meta))]
    if rng.random() < 0.4:
        del meta[key]
    else:
        meta[key] = random_value(rng)
    return meta


def damage(ext: str, data: bytes, rng: np.random.Generator, where: Path) -> tuple[bytes, str]:
    """Damaged bytes of a results file and how they were damaged."""
    how = rng.choice(["truncate", "flip", "meta", "drop", "empty", "noise", "other"])
    if how == "truncate":
        return data[: rng.integers(0, len(data))], how
    if how == "flip":
        b = bytearray(data)
        for _ in range(rng.integers(1, 4)):
            b[rng.integers(len(b))] ^= int(rng.integers(1, 256))
        return bytes(b), how
    if how == "empty":
        return b"", how
    if how == "noise":
        return rng.bytes(int(rng.integers(1, 2000))), how
    if how == "other":
        # Another program's .npz (or an object array, which numpy reads only with allow_pickle).
        buf = io.BytesIO()
        if rng.random() < 0.5:
            np.savez(buf, a=rng.random(5), metadata=np.array([1, 2]))
        else:
            np.save(buf, np.array([{"a": 1}], dtype=object), allow_pickle=True)
        return buf.getvalue(), how
    src = where / f"src{ext}"
    src.write_bytes(data)
    if ext == ".npz":
        with np.load(src, allow_pickle=False) as z:
            arrays = {k: z[k] for k in z.files}
        meta = json.loads(str(arrays["metadata"]))
        if how == "meta":
            arrays["metadata"] = np.array(json.dumps(damage_meta(meta, rng)))
        else:
            name = sorted(arrays)[rng.integers(len(arrays))]
            if rng.random() < 0.5:
                del arrays[name]
            else:
                arrays[name] = np.array(["x"] * 3) if rng.random() < 0.5 else arrays[name].ravel()[:-1]
        buf = io.BytesIO()
        np.savez(buf, **arrays)
        return buf.getvalue(), how
    if ext == ".parquet":
        import pyarrow.parquet as pq

        table = pq.read_table(src)
        meta = json.loads(table.schema.metadata[b"planardyn"])
        if how == "meta":
            table = table.replace_schema_metadata({"planardyn": json.dumps(damage_meta(meta, rng))})
        else:
            table = table.remove_column(int(rng.integers(table.num_columns))).replace_schema_metadata(
                table.schema.metadata)
        buf = io.BytesIO()
        pq.write_table(table, buf)
        return buf.getvalue(), how
    lines = data.decode().splitlines(keepends=True)
    comment = [ln for ln in lines if ln.startswith("#")]
    body = lines[len(comment):]
    if how == "meta":
        meta = json.loads("".join(ln[2:] for ln in comment))
        comment = [f"# {ln}\n" for ln in json.dumps(damage_meta(meta, rng), indent=1).splitlines()]
    elif rng.random() < 0.5:
        del body[rng.integers(len(body))]
    else:
        col = int(rng.integers(len(body[0].split(","))))
        body = [",".join(v for k, v in enumerate(ln.rstrip("\n").split(",")) if k != col) + "\n" for ln in body]
    return "".join(comment + body).encode(), how


def option(rng: np.random.Generator) -> str:
    if rng.random() < 0.5:
        return WORDS[rng.integers(len(WORDS))]
    return repr(float(rng.choice([-1, 1]) * 10 ** rng.uniform(-320, 308)))


def command(rng: np.random.Generator, path: Path, out: Path) -> list[str]:
    """A random command on ``path``; its options random, kept cheap to run."""
    kind = rng.choice(["plot", "animate", "inverse", "simulate"])
    if kind == "plot":
        argv = ["plot", str(path), "-o", str(out / "fig.png")]
        if rng.random() < 0.5:
            argv += ["--dpi", option(rng) if rng.random() < 0.9 else "20"]
        if rng.random() < 0.3:
            argv.append("--torque-speed")
        return argv
    if kind == "animate":
        argv = ["animate", str(MODEL), str(path), "-o", str(out / "view.html")]
        for name in ("--fps", "--speed"):
            if rng.random() < 0.5:
                argv += [name, option(rng)]
        return argv
    if kind == "inverse":
        return ["inverse", str(MODEL), "--motion", str(path)] + (["-o", str(out / "inv.npz")] if rng.random() < 0.5 else [])
    argv = ["simulate", str(MODEL), "--no-progress", "-o", str(out / "sim.npz")]
    for name in ("--t-end", "--rtol", "--atol", "--dt", "--output-dt"):
        if rng.random() < 0.4:
            argv += [name, option(rng)]
    if rng.random() < 0.2:
        argv += ["--method", str(rng.choice(["rk4", "dopri5", "radau5", "dop853", "euler", ""]))]
    # Bounded work: a random --max-steps replaces the cap only where the run is short.
    steps = option(rng) if rng.random() < 0.2 else str(rng.integers(1, 300))
    if steps.lstrip("-").isdigit() and abs(int(steps)) > 300:
        argv += ["--t-end", "0.01"]
    return argv + ["--max-steps", steps]


def same_as_written(path: Path, original: pd.SimulationResult) -> bool:
    """The file reads back as the result that was written (damage that changed nothing read)."""
    back = pd.read_results(path)
    fields = ("t", "q", "qd", "qdd", "tau", "x", "xd", "sigma", "residual", "partitioned")
    return all(np.array_equal(getattr(back, f), getattr(original, f), equal_nan=True) for f in fields) and (
        {k: v for k, v in back.metadata.items() if k != "path"}
        == {k: v for k, v in original.metadata.items() if k != "path"}
        and (back.status, back.message, back.stats) == (original.status, original.message, original.stats))


def motion_table(argv: list[str], path: Path) -> bool:
    """``inverse`` takes a CSV that is no longer a results file (its metadata's 'format'
    changed) as what it then is: a motion table with a t column and one per coordinate."""
    try:
        pd.read_results(path)
    except ValueError as e:
        return argv[0] == "inverse" and path.suffix == ".csv" and "not a planardyn results file" in str(e)
    return False


def check(argv: list[str], path: Path, damaged: bool, harmless: bool, original: pd.SimulationResult) -> int:
    code, err = cli_run(*argv)
    where = f"planardyn {' '.join(argv)}"
    assert code in (0, 1, 2), f"{where}: exit {code}\n{err}"
    assert "Traceback" not in err and "planardyn: unexpected " not in err, f"{where}:\n{err}"
    lines = [ln for ln in err.splitlines() if ln.startswith("planardyn:")]
    assert len(lines) <= 2, f"{where}: several messages\n{err}"
    reads = argv[0] != "simulate"
    if reads and damaged and code == 2 and "error: argument" not in err and str(MODEL) not in err:
        assert str(path) in err, f"{where}: the message does not name the file\n{err}"
    if reads and damaged and not harmless:
        assert code != 0 or motion_table(argv, path) or same_as_written(path, original), (
            f"{where}: a damaged file misread as a success")
    return code


def test_cli_fuzz(originals, tmp_path):
    """Damaged results files and random options: exit 0, 1 or 2, a message, no traceback."""
    rng = np.random.default_rng(SEED)
    failures: list[str] = []
    written = {}
    for ext in FORMATS:
        write_input(tmp_path / f"written{ext}", originals[ext])
        written[ext] = pd.read_results(tmp_path / f"written{ext}")
    outcomes: Counter[tuple[str, int]] = Counter()
    for k in range(N_INPUTS):
        ext = FORMATS[k % 3]
        path = tmp_path / f"input{ext}"
        damaged = rng.random() < 0.8
        if damaged:
            data, how = damage(ext, originals[ext], rng, tmp_path)
        else:
            data, how = originals[ext], "intact"
        write_input(path, data)
        argv = command(rng, path, tmp_path)
        # Harmless: the final newline cut off, or the metadata's checksum itself dropped.
        harmless = data.rstrip() == originals[ext].rstrip() or (how == "meta" and b'"checksum"' not in data)
        try:
            outcomes[(f"{argv[0]} {how}", check(argv, path, damaged, harmless, written[ext]))] += 1
        except AssertionError as e:  # the whole campaign runs; every failure is listed at the end
            failures.append(str(e).splitlines()[0] + " | " + " ".join(str(e).splitlines()[1:2]))
    print(f"\n{N_INPUTS} inputs, seed {SEED}: {len(failures)} failures")
    assert not failures, "\n".join(failures[:10])
    # Every kind of damage was tried.
    assert {h.split()[1] for h, _ in outcomes} >= {"truncate", "flip", "meta", "drop"} or N_INPUTS < 100
    print(f"\n{N_INPUTS} inputs, seed {SEED}: " + ", ".join(f"{h} exit {c}: {n}" for (h, c), n in sorted(outcomes.items())))


def test_broken_pipe_ends_quietly():
    """``planardyn check MODEL | head -1``: no BrokenPipeError traceback, exit 0."""
    import subprocess
    import sys

    env = dict(os.environ, PYTHONPATH=os.pathsep.join(sys.path))
    cmd = f"{sys.executable} -m planardyn check {MODEL} | head -c 10; exit ${{PIPESTATUS[0]}}"
    p = subprocess.run(["bash", "-c", cmd], capture_output=True, text=True, env=env, timeout=60)
    assert p.returncode == 0, p.stderr
    assert p.stdout == "model: fiv" and p.stderr == "", p.stderr


def test_npz_needing_pickle_is_refused_with_its_name(tmp_path):
    """A .npz of object arrays was read on numpy's advice to pass allow_pickle; now refused."""
    p = tmp_path / "other.npz"
    np.savez(p, metadata=np.array([{"format": "planardyn-results"}], dtype=object))
    code, err = cli_run(*["plot", str(p)])
    assert code == 2 and str(p) in err and "allow_pickle" not in err, err
    with zipfile.ZipFile(p) as z:
        assert z.namelist() == ["metadata.npy"]


# ---------------------------------------------------------------- the options issues 12-16 added (issue 23)

#: Every option issues 12-16 added to the commands of cli.py, with where its value goes
#: ({} is the hostile word). ``planardyn size --distribution/--preload`` and ``planardyn plan``
#: are the planning helper's (its fuzz test lists them).
NEW_OPTIONS = [
    ("simulate", "--speed", "theta1={}"),  # issue 12: prescribed motion
    ("simulate", "--speed", "{}=1rev/s"),
    ("simulate", "--stop-when", "theta1>{}"),  # issue 12: events
    ("simulate", "--stop-when", "{}=1"),
    ("animate", "--trace", "{}"),  # issue 12: point traces, viewer channels
    ("animate", "--channel", "{}"),
    ("identify", "--cutoff", "{}"),  # issue 15: identification
    ("identify", "--validate", "{}.csv"),
    ("demo", "--model", "{}"),  # issue 12: the demo
]


@pytest.fixture(scope="module")
def measured(tmp_path_factory) -> Path:
    """A measured motion of the five-bar (t, q, tau at 200 Hz over 2 s) along a two-tone
    motion of both cranks, which identifies every base parameter."""
    import csv

    mech = pd.load(MODEL)
    t = np.arange(0.0, 2.0, 0.005)
    w = 2 * np.pi * np.array([[1.0, 3.0], [2.0, 1.0]])
    q = mech.q0 + 0.15 * np.sin(t[:, None, None] * w).sum(axis=2)
    qd = 0.15 * (np.cos(t[:, None, None] * w) * w).sum(axis=2)
    qdd = -0.15 * (np.sin(t[:, None, None] * w) * w**2).sum(axis=2)
    path = tmp_path_factory.mktemp("measured") / "measured.csv"
    with open(path, "w", newline="") as f:
        out = csv.writer(f)
        out.writerow(["t", "theta1", "theta2", "tau_theta1", "tau_theta2"])
        out.writerows(np.column_stack([t, q, mech.inverse_dynamics(q, qd, qdd)]).tolist())
    return path


def option_command(command: str, option: str, value: str, run: Path, measured: Path, out: Path) -> list[str]:
    """The command line trying ``option value``, kept cheap to run."""
    if command == "simulate":
        return ["simulate", str(MODEL), "--t-end", "0.01", "--max-steps", "300", "--no-progress", option, value]
    if command == "animate":
        return ["animate", str(run), "-o", str(out / "view.html"), option, value]
    if command == "identify":
        cutoff = [] if option == "--cutoff" else ["--cutoff", "10"]
        return ["identify", str(MODEL), str(measured), *cutoff, option, value]
    return ["demo", "--out", str(out / "demo"), option, value]


@pytest.mark.parametrize(("command", "option", "form"), NEW_OPTIONS, ids=lambda v: str(v))
def test_new_options_take_any_value_and_name_themselves(originals, measured, tmp_path, command, option, form):
    """Each option with every hostile word: exit 0 or 1, or exit 2 with one message naming the
    option (or the value given), never a traceback or a library's words."""
    run = tmp_path / "run.npz"
    run.write_bytes(originals[".npz"])
    failures = []
    for word in WORDS:
        value = form.format(word)
        argv = option_command(command, option, value, run, measured, tmp_path)
        code, err = cli_run(*argv)
        where = f"planardyn {' '.join(argv)}: exit {code}: {err.strip()[:300]}"
        ok = code in (0, 1, 2) and "Traceback" not in err and "unexpected" not in err
        ok = ok and len([ln for ln in err.splitlines() if ln.startswith("planardyn")]) <= 2
        if code == 2:
            ok = ok and (option in err or (value.strip() and value.strip() in err))
        if not ok:
            failures.append(where)
    assert not failures, "\n".join(failures)
