#!/usr/bin/env bash
# The reference runs: thirteen `--json` runs across the scenes, integrators, friction laws
# and grounds, written one file each. A change meant to keep the results to the bit is
# checked by running this with the old and the new binary and comparing the folders:
#
#   scripts/reference_runs.sh OLD_BINARY /tmp/ref-old
#   scripts/reference_runs.sh target/release/slidebase /tmp/ref-new
#   diff -r /tmp/ref-old /tmp/ref-new && echo "same bits"
#
# The whole set takes a few seconds.
set -euo pipefail
bin=${1:?usage: reference_runs.sh SLIDEBASE_BINARY OUT_DIR}
out=${2:?usage: reference_runs.sh SLIDEBASE_BINARY OUT_DIR}
mkdir -p "$out"

one() {
    local name=$1
    shift
    # The wall time is the one field that differs between two runs of one binary.
    "$bin" run --json "$@" 2> "$out/$name.stderr" | sed -E 's/"wall_time_s":[^,}]*,?//' \
        > "$out/$name.json" || echo "exit $?" >> "$out/$name.stderr"
}

one two-block-resonance    --alpha 0.5 --friction 0.1 --freq-ratio 1 --duration 100
one two-block-slow         --alpha 0.9 --friction 0.05 --freq-ratio 0.5 --duration 100
one two-block-fast-trap    --alpha 0.1 --friction 0.25 --freq-ratio 5 --duration 20 --integrator trapezoidal
one two-block-hht          --friction 0.05 --freq-ratio 2 --duration 20 --integrator hht:0.1
one two-block-velocity-law --friction-law velocity:0.05,0.1,20 --duration 20
one two-block-damped-large --damping 0.05 --ground large-mass --duration 20
one three-storey-sliding   --scene three-storey --duration 31
one three-storey-fixed     --scene three-storey --fixed-base --duration 31
one three-storey-pendulum  --scene three-storey --bearing pendulum:2 --duration 10
one frame-10               --scene frame:10 --duration 10
one block-kobe-vertical    --scene block --record kobe-nishi-akashi-000 --vertical-record el-centro-up --duration 10
one friction-pendulum      --scene friction-pendulum --duration 10
one wall-4-kobe            --scene wall:4 --record kobe-nishi-akashi-000 --duration 10
