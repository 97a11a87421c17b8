#!/usr/bin/env bash
# One command for the whole benchmark suite (docs/benchmarks.md):
#
#   benchmarks/run.sh [--quick] [--only four-bar five-bar 3-rrr andrews] [--no-criterion] [--verbose]
#
# --only runs some mechanisms and keeps the others' results (each with its own date) in
# results.json, results.md and docs/benchmarks.md; --quick times the winners in fewer rounds (the
# search for each method's cheapest setting is the same); --verbose prints every run of the search.
#
# 1. ./dev setup: builds planardyn's extension from the current sources into python/.
# 2. benchmarks/.venv-peers: a venv of its own with the other tools from PyPI (mujoco, pin,
#    exudyn) plus numpy, matplotlib, pyyaml, pytest (for benchmarks/test_common.py). A tool
#    whose install fails is left out and reported by bench.py as not available, never hidden.
# 3. benchmarks/rust-sim: the same simulate call from Rust, for the Python-overhead figure.
# 4. bench.py: every measurement in one run; writes benchmarks/results/ and the generated
#    section of docs/benchmarks.md. It prints, per mechanism, each method's cheapest passing
#    setting, the winners' times and ratios, and the load average; the machine's load is printed
#    here before and after as well (wall times on a shared machine follow it).
set -euo pipefail

HERE="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
ROOT="$(dirname "$HERE")"
VENV="$HERE/.venv-peers"
PY="$VENV/bin/python"
PEERS=(mujoco pin exudyn)
BASE=(numpy matplotlib pyyaml pytest)

say() { printf '\033[1m==> %s\033[0m\n' "$*" >&2; }

say "planardyn: ./dev setup"
"$ROOT/dev" setup

if [[ ! -x "$PY" ]]; then
    say "creating $VENV"
    python3 -m venv "$VENV"
    "$PY" -m pip install --quiet --disable-pip-version-check --upgrade pip
fi
stamp="$VENV/.installed"
want="${BASE[*]} ${PEERS[*]}"
if [[ ! -f "$stamp" || "$(cat "$stamp")" != "$want" ]]; then
    say "installing ${BASE[*]} into $VENV"
    "$PY" -m pip install --quiet --disable-pip-version-check "${BASE[@]}"
    for pkg in "${PEERS[@]}"; do
        say "installing $pkg"
        # One at a time: one that will not install must not keep the others out.
        "$PY" -m pip install --quiet --disable-pip-version-check "$pkg" \
            || printf 'run.sh: pip could not install %s: bench.py reports it as not available\n' "$pkg" >&2
    done
    echo "$want" > "$stamp"
fi

say "building benchmarks/rust-sim (release)"
# Start from the repository's lock file so that the core builds with the same dependency
# versions as the Python extension.
cp "$ROOT/Cargo.lock" "$HERE/rust-sim/Cargo.lock"
CARGO_TARGET_DIR="$HERE/.target" cargo build --release --quiet --manifest-path "$HERE/rust-sim/Cargo.toml"

say "running bench.py on $(nproc) CPUs; load: $(uptime)"
cd "$ROOT"
PYTHONPATH="$ROOT/python${PYTHONPATH:+:$PYTHONPATH}" "$PY" "$HERE/bench.py" "$@"
say "done; load: $(uptime)"
