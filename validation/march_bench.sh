#!/usr/bin/env bash
# The periodic LCP against explicit time marching at equal accuracy on the real blade (issue 23):
# both reductions (massless boundary, Craig–Bampton), rigid and compliant tips, ω = 2300 rad/s
# (the benchmark's) and 2130 rad/s (not tuned on). One `examples/march_bench.rs` run per line of
# the table; its output (reference, every run's error and CPU) goes to out/march-bench/*.txt.
# Needs examples/real-blade/job/ (bash examples/real_blade.sh writes it) and `cargo build --release
# --example march_bench`. About 5–30 min per case on 2 loaded cores.
#   CASES="rigid-massless-2300 ..." to run a subset; OURS_TOLS / MARCH_TOL to change the ladders;
#   MARCH_N=none to run only the set-up, the reference and ours.
set -euo pipefail
cd "$(dirname "$0")/.."
out=out/march-bench
mkdir -p "$out"
bin=target/release/examples/march_bench
ours_tols=${OURS_TOLS:-1e-2,1e-3,1e-4}
march_tol=${MARCH_TOL:-1e-2,1e-3,1e-4,1e-5,1e-6}
# A scene copy with scheme = "auto" (the tolerance is set per run) and the reduction asked for.
scene() { # source reduction -> path
  local f="$out/$(basename "$1" .toml)-$2.toml"
  sed -e 's#^calculix = "job/blade"#calculix = "../../examples/real-blade/job/blade"#' \
      -e "s/^method = \"massless-boundary\"/method = \"$2\"/" \
      -e 's/^scheme = "cds"/scheme = "auto"\ntolerance = 1e-3\nmax_steps = 32768/' \
      -e '/^steps = [0-9]*$/d' -e '/^pairing = "same"$/d' "$1" > "$f"
  echo "$f"
}
# case: tips-reduction-omega; march steps: multiples of the stable step (sN) for the stiff
# Craig–Bampton model, fixed ladders for the massless boundary (its stable step is 384 at 2300).
for c in ${CASES:-rigid-massless-boundary-2300 rigid-craig-bampton-2300 compliant-massless-boundary-2300 compliant-craig-bampton-2300 rigid-massless-boundary-2130 rigid-craig-bampton-2130 compliant-massless-boundary-2130 compliant-craig-bampton-2130}; do
  tips=${c%%-*}; rest=${c#*-}; omega=${rest##*-}; red=${rest%-*}
  src=examples/real-blade/blade.toml; [ "$tips" = compliant ] && src=examples/real-blade/blade-compliant.toml
  case "$red" in
    massless-boundary) ns=${MARCH_N:-s1.05,1024,2048,4096}; refk=${REF_K:-2048} ;;
    craig-bampton) ns=${MARCH_N:-s1.05,s2}; refk=${REF_K:-16384} ;;
  esac
  s=$(scene "$src" "$red")
  echo "== $c: $bin $s $omega $refk $ours_tols $ns $march_tol"
  uptime
  /usr/bin/time -v "$bin" "$s" "$omega" "$refk" "$ours_tols" "$ns" "$march_tol" 2> "$out/$c.time" | tee "$out/$c.txt"
  grep -E "Maximum resident|User time|System time|Elapsed" "$out/$c.time"
done
