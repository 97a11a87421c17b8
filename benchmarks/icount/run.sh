#!/usr/bin/env bash
# Instructions per evaluation for the models of the forward_dynamics bench: same stage point
# ("same") and alternating stage points 1 mrad apart ("alt"); then the stated limit, the
# hand-coded closed-form four-bar (src/four_bar_limit.rs) at the same points, and planardyn's
# four-bar as a multiple of it. Needs valgrind.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")"
cargo build --release -q
bin=target/release/planardyn-icount
ir() { valgrind --tool=callgrind --callgrind-out-file=/dev/null "$bin" "$@" 2>&1 | grep -oP "Collected : \K[0-9]+"; }
per_eval() { echo $(( ($(ir "../../examples/models/$1.yaml" 1000 "$2") - $(ir "../../examples/models/$1.yaml" 0 "$2")) / 1000 )); }
declare -A four_bar
for f in four-bar-gravity five-bar 3-rrr andrews-squeezer slider-crank scotch-yoke gear-train; do
    for case in same alt; do
        n=$(per_eval "$f" "$case")
        echo "$f $case $n"
        if [ "$f" = four-bar-gravity ]; then four_bar[$case]=$n; fi
    done
done
for case in same alt; do
    n=$(per_eval four-bar-gravity "limit-$case")
    echo "four-bar-limit $case $n"
    echo "four-bar / limit $case $(awk -v a="${four_bar[$case]}" -v b="$n" 'BEGIN { printf "%.1f", a / b }')"
done
# The type II measure from the closed forms, per call.
for f in four-bar-gravity slider-crank scotch-yoke gear-train 3-rrr; do
    a=$(ir "../../examples/models/$f.yaml" 0 sigma)
    b=$(ir "../../examples/models/$f.yaml" 1000 sigma)
    echo "$f sigma $(( (b - a) / 1000 ))"
done
