#!/bin/bash
# Coarse rigid blade, Craig–Bampton vs massless boundary (η = 20): time and error against each model's own cds reference at k = 4096.
P=${P:-target/release/periodic-contact}
S=$(pwd)/fmu/scenes/blade-casing-rigid.toml; P=$(realpath $P)
W=$(mktemp -d); cd $W
mk() { # method scheme steps pairing-line
  sed -e "s/method = \"craig-bampton\"/method = \"$1\"/" -e "s/^scheme = \"cds\"/scheme = \"$2\"/" -e "s/^steps = \"auto\".*/steps = $3/" -e '/^pairing = /d' $S > s-$1-$2-$3.toml
}
for m in craig-bampton massless-boundary; do
  mk $m cds 4096; $P solve s-$m-cds-4096.toml --no-estimate -o ref-$m.json 2>&1 | grep -E "solved|error" | sed "s/^/ref $m: /"
  for sc in cds galerkin bds2 bds1; do for k in 256 512 1024 2048; do
    mk $m $sc $k
    out=$( $P solve s-$m-$sc-$k.toml --no-estimate -o r-$m-$sc-$k.json 2>&1 | grep -oE "residual [^,]*, [0-9.]+ s" | grep -oE "[0-9.]+ s$" )
    python3 - $m $sc $k "$out" <<'PY'
import json,sys,os
m,sc,k,t=sys.argv[1:]
f=f"r-{m}-{sc}-{k}.json"
if not os.path.exists(f) or os.path.getmtime(f) < os.path.getmtime(f"s-{m}-{sc}-{k}.toml"):
    print(f"{m:18s} {sc:8s} k={k:>5}: refused/failed"); sys.exit()
r=json.load(open(f)); ref=json.load(open(f"ref-{m}.json"))
k=int(k); step=4096//k
err=0; ptp=0
for key,x in r["displacement"].items():
    xr=ref["displacement"][key][::step]
    err=max(err,max(abs(a-b) for a,b in zip(x,xr))); ptp=max(ptp,max(xr)-min(xr))
print(f"{m:18s} {sc:8s} k={k:>5}: LCP solve {t}, error {err/ptp:.2e} of peak-to-peak")
PY
  done; done
done
