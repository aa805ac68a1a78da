#!/bin/bash
# Newmark's sliding block: DDA (two integrators) against the exact rigid block, whole
# records, three friction laws; prints the table of docs/sliding-block.md.
# usage: scripts/block_table.sh target/release/slidebase [--vertical-record el-centro-up]
B=$1
shift
EXTRA="$*"
for rec in ${RECORDS:-el-centro kobe-nishi-akashi-000}; do
for law in 0.15 static-kinetic:0.2,0.12 velocity:0.08,0.16,10; do
  ex=$($B run --scene block --record $rec --friction-law $law --model mass-spring $EXTRA --json)
  for integ in generalized-alpha:0 trapezoidal; do
    dd=$($B run --scene block --record $rec --friction-law $law --integrator $integ $EXTRA --json)
    python3 - "$ex" "$dd" "$rec" "$law" "$integ" <<'PY'
import json,sys
e=json.loads(sys.argv[1]); d=json.loads(sys.argv[2])
rel=lambda a,b: 100*(a-b)/b
print(f"| {sys.argv[3]} | {sys.argv[4]} | {sys.argv[5]} | {e['max_slip_m']*1000:.2f} | {d['max_slip_m']*1000:.2f} | {rel(d['max_slip_m'],e['max_slip_m']):+.2f} % | {e['residual_slip_m']*1000:.2f} | {d['residual_slip_m']*1000:.2f} | {(d['residual_slip_m']-e['residual_slip_m'])*1000:+.2f} | {e['peak_base_accel_g']:.4f} | {d['peak_base_accel_g']:.4f} | {d['energy_residual_rel']:.1e} |")
PY
  done
done
done
