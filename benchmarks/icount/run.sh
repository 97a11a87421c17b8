#!/usr/bin/env bash
# Instructions per evaluation for the models of the forward_dynamics bench: same stage point
# ("same") and alternating stage points 1 mrad apart ("alt"). Needs valgrind.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")"
cargo build --release -q
bin=target/release/planardyn-icount
ir() { valgrind --tool=callgrind --callgrind-out-file=/dev/null "$bin" "$@" 2>&1 | grep -oP "Collected : \K[0-9]+"; }
for f in four-bar-gravity five-bar 3-rrr andrews-squeezer slider-crank scotch-yoke gear-train; do
    for case in same alt; do
        a=$(ir "../../examples/models/$f.yaml" 0 "$case")
        b=$(ir "../../examples/models/$f.yaml" 1000 "$case")
        echo "$f $case $(( (b - a) / 1000 ))"
    done
done
# The type II measure from the closed forms, per call.
for f in four-bar-gravity slider-crank scotch-yoke gear-train 3-rrr; do
    a=$(ir "../../examples/models/$f.yaml" 0 sigma)
    b=$(ir "../../examples/models/$f.yaml" 1000 sigma)
    echo "$f sigma $(( (b - a) / 1000 ))"
done
