#!/usr/bin/env bash
# Instructions per evaluation for the models of the forward_dynamics bench, at stage points
# 1 mrad apart in turn ("alt": every evaluation a new point, as in an integration); then the
# stated limit, the hand-coded closed-form four-bar (src/four_bar_limit.rs) at the same points,
# and planardyn's four-bar as a multiple of it. The "same" case (one point asked again and
# again) now measures `MechanismOde::rhs` handing back the evaluation it holds, which an
# integration meets only when a chart switch asks again for its point: printed once, for the
# four-bar. Needs valgrind.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")"
cargo build --release -q
bin=target/release/planardyn-icount
ir() { valgrind --tool=callgrind --callgrind-out-file=/dev/null "$bin" "$@" 2>&1 | grep -oP "Collected : \K[0-9]+"; }
per_eval() { echo $(( ($(ir "../../examples/models/$1.yaml" 1000 "$2") - $(ir "../../examples/models/$1.yaml" 0 "$2")) / 1000 )); }
for f in four-bar-gravity five-bar 3-rrr andrews-squeezer slider-crank scotch-yoke gear-train; do
    n=$(per_eval "$f" alt)
    echo "$f $n"
    if [ "$f" = four-bar-gravity ]; then four_bar=$n; fi
done
echo "four-bar held evaluation handed back (same point) $(per_eval four-bar-gravity same)"
n=$(per_eval four-bar-gravity limit-alt)
echo "four-bar-limit $n"
echo "four-bar / limit $(awk -v a="$four_bar" -v b="$n" 'BEGIN { printf "%.1f", a / b }')"
# The type II measure from the closed forms, per call.
for f in four-bar-gravity slider-crank scotch-yoke gear-train 3-rrr; do
    a=$(ir "../../examples/models/$f.yaml" 0 sigma)
    b=$(ir "../../examples/models/$f.yaml" 1000 sigma)
    echo "$f sigma $(( (b - a) / 1000 ))"
done
