#!/bin/sh
# Times the C reference edge loop (edge_loop.c) on the bench mesh of `fluid-solver bench` and
# prints the solver's own bench JSON next to it, for comparing ns per edge of the edge loop
# (single thread). A measurement tool: nothing in the product uses it.
#
# Usage: fluid-solver/bench/run-c-reference.sh [NODES]   (run from the workspace root; needs gcc
# and a release build: cargo build --release -p fluid-solver)
# Environment: CFLAGS to override the C flags (default -O3 -march=native -fopenmp-simd -ffp-contract=off -fno-math-errno).
set -eu
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
nodes=${1:-200000}
bin="$root/target/release/fluid-solver"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cflags=${CFLAGS:--O3 -march=native -fopenmp-simd -ffp-contract=off -fno-math-errno}
# shellcheck disable=SC2086
gcc -std=c99 -Wall -Wextra $cflags -o "$work/edge_loop" "$here/edge_loop.c" -lm
echo "# fluid-solver bench (edge_loop_ns_per_edge is the Rust edge loop):"
"$bin" bench --nodes "$nodes" --steps 5 --threads 1 --dump-edges "$work/edges.bin"
echo "# C reference ($cflags):"
"$work/edge_loop" "$work/edges.bin" 11
