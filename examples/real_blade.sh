#!/bin/bash
# The real-blade benchmark (issue 23; README "Real-blade benchmark"): deck → CalculiX → read →
# massless-boundary reduction → rigid-contact speed sweep with every point's error estimate →
# explicit time marching on the same reduced model at equal accuracy. Run from the repository
# root after `cargo build --release`:   bash examples/real_blade.sh
#   POINTS=200 (sweep points), FROM=2000 TO=2600 (ω = 2Ω [rad/s]), MARCH_AT=2300,
#   CB=1 also solves the Craig–Bampton model once (cds at k = 16 384, started from a bds1 pilot: about 14 s of CPU).
set -euo pipefail
P=$(realpath ${P:-target/release/periodic-contact})
POINTS=${POINTS:-200}; FROM=${FROM:-2000}; TO=${TO:-2600}; MARCH_AT=${MARCH_AT:-2300}
S=examples/real-blade; J=$S/job; OUT=${OUT:-out/real-blade}
mkdir -p $J $OUT
T="/usr/bin/time -f %e_s_%M_KiB"
echo "== 1. the deck (project's generator) and CalculiX's assembly"
$P deck $S/mesh.toml -o $J/blade.inp
( cd $J && $T ccx blade > ccx.log 2> ccx.time ) ; echo "ccx: $(tail -1 $J/ccx.time) (wall, peak RSS); $(wc -l < $J/blade.dof) DOFs in blade.dof"
echo "== 2. one point (ω = $MARCH_AT rad/s): read, reduce, solve, estimate"
$T $P solve $S/blade.toml --frequency $MARCH_AT -o $OUT/point.json 2> $OUT/point.log || true
grep -E "reduced|solver:|error estimate|solved|_s_" $OUT/point.log | cut -c1-220
echo "== 3. the sweep: $POINTS points, ω = $FROM … $TO rad/s, every point estimated"
$T $P sweep $S/blade.toml --from $FROM --to $TO --points $POINTS --estimate --quiet --no-plot -o $OUT/sweep.csv 2> $OUT/sweep.log || true
grep -E "reduced|sweep:|error estimates|failed at|total|_s_" $OUT/sweep.log | cut -c1-260
python3 - $OUT/sweep.csv <<'PY'
import csv, sys
rows = list(csv.DictReader(open(sys.argv[1])))
est = [float(r["error_estimate_relative"]) for r in rows if r["status"] == "solved" and r["error_estimate_relative"] != "nan"]
t = [float(r["time_s"]) for r in rows]
print(f"points {len(rows)}, solved {sum(r['status'] == 'solved' for r in rows)}, estimated {len(est)}, "
      f"estimate ≤ 1e-3 at {sum(e <= 1e-3 for e in est)}, worst {max(est):.2e}, median {sorted(est)[len(est)//2]:.2e}; "
      f"time per point (k and k/2) worst {max(t):.2f} s, median {sorted(t)[len(t)//2]:.2f} s, sum {sum(t):.1f} s")
PY
echo "== 4. explicit time marching on the same reduced model at ω = $MARCH_AT (stable step; reference: the LCP at 4k)"
$T $P sweep $S/blade.toml --from $MARCH_AT --to $MARCH_AT --points 1 --march-at $MARCH_AT --march-tol 1e-4,1e-6 --quiet --no-plot -o $OUT/march.csv 2> $OUT/march.log | tee $OUT/march.txt || true
grep -E "reduced|_s_|error" $OUT/march.log | cut -c1-220
if [ "${CB:-0}" = 1 ]; then
  echo "== 5. Craig–Bampton (fixed-interface modes, rigid impacts on massive DOFs), steps = auto"
  sed -e 's/^method = "massless-boundary"/method = "craig-bampton"/' -e 's/^steps = 1024/steps = "auto"/' -e 's/^pairing = "same"/pairing = "forward"/' \
    -e 's|calculix = "job/blade"|calculix = "'$(realpath $J)'/blade"|' $S/blade.toml > $OUT/real-blade-cb.toml
  $T $P solve $OUT/real-blade-cb.toml --frequency $MARCH_AT -o $OUT/cb.json 2> $OUT/cb.log || true
  grep -E "reduced|auto|solver:|error estimate|solved|_s_" $OUT/cb.log | cut -c1-220
fi
