"""The CLI's grid answers on a compliant blade scene against the exact-flow orbit (issue 23).

For each reduction (Craig–Bampton and the massless boundary, whichever the scene ships): export
the model the scene solves, compute its exact orbit (exact_flow.py, guess from a bds2 answer), then
solve with each scheme at k, 2k, 4k, … from its smallest stable k, until the error is below 1e-4
(or k_max), timing each solve; with --auto also `scheme = "auto"` at tolerance 1e-4. Prints a table
and writes JSON with the rows, the observed orders and the k that reaches 1e-4.

    python validation/exact_flow_blade.py [--scene S.toml] [--frequency W] [--cli target/release/periodic-contact]
        [--kmax 8192] [--auto] [-o out.json]

Default scene: the coarse two-lobe blade (fmu/scenes/blade-two-lobes.toml); the real blade with
compliant tips is examples/real-blade/blade-compliant.toml (CalculiX files: examples/real_blade.sh).
"""
from __future__ import annotations

import argparse
import json
import os
import re
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)

from exact_flow import ExactFlow, ContactModel, compare_with_grid  # noqa: E402

import numpy as np  # noqa: E402

SCENE = os.path.join(HERE, "..", "fmu", "scenes", "blade-two-lobes.toml")
# (scheme, order it should show): fourier's is that of a compliant contact's kink in the jerk
SCHEMES = (("bds2", 2), ("fourier", 2), ("galerkin", 2), ("cds", 2))
TARGET = 1e-4


def variant(text: str, method: str, scheme: str, steps: int) -> str:
    text = re.sub(r'^method = "[\w-]+"', f'method = "{method}"', text, flags=re.M)
    text = re.sub(r'^scheme = "\w+"', f'scheme = "{scheme}"', text, flags=re.M)
    text = re.sub(r"^steps = \d+", f"steps = {steps}", text, flags=re.M)
    return re.sub(r'^pairing = "\w+"\n', "", text, flags=re.M)


def localised(text: str, scene_dir: str, frequency=None) -> str:
    """The scene text runnable from another folder: its file references made absolute; with
    `frequency`, the excitation's ω replaced."""
    def absolute(m):
        return f'{m.group(1)}"{os.path.join(scene_dir, m.group(2))}"'
    text = re.sub(r'^(calculix = |profile = )"([^"/][^"]*)"', absolute, text, flags=re.M)
    text = re.sub(r'(matrix_market = )"([^"/][^"]*)"', absolute, text)
    if frequency is not None:
        text = re.sub(r"^frequency = [0-9.eE+-]+", f"frequency = {frequency}", text, count=1, flags=re.M)
    return text


def auto_variant(text: str, method: str, tolerance: float) -> str:
    """`scheme = "auto"` at `tolerance` (the CLI chooses scheme, pairing and k)."""
    text = variant(text, method, "auto", 256)
    text = re.sub(r"^steps = \d+\n", "", text, flags=re.M)
    return re.sub(r'^scheme = "auto"', f'scheme = "auto"\ntolerance = {tolerance}', text, flags=re.M)


def solve(cli, work, text, name, extra=(), timeout=900, ok=(0,)):
    """(result JSON or None, wall s, stderr); `ok`: the exit statuses that still carry a result."""
    scene = os.path.join(work, f"{name}.toml")
    out = os.path.join(work, f"{name}.json")
    open(scene, "w").write(text)
    t = time.perf_counter()
    try:
        p = subprocess.run([cli, "solve", scene, "--no-estimate", "-o", out, *extra], capture_output=True, text=True, timeout=timeout)
    except subprocess.TimeoutExpired:
        return None, timeout, "timeout"
    wall = time.perf_counter() - t
    if p.returncode not in ok or not os.path.exists(out):
        return None, wall, p.stderr.strip()
    return json.load(open(out)), wall, p.stderr


def main(argv=None):
    ap = argparse.ArgumentParser()
    ap.add_argument("--scene", default=SCENE)
    ap.add_argument("--frequency", type=float, default=None, help="ω [rad/s] instead of the scene's")
    ap.add_argument("--auto", action="store_true", help='also scheme = "auto" at tolerance 1e-4')
    ap.add_argument("--cli", default=os.path.join(HERE, "..", "target", "release", "periodic-contact"))
    ap.add_argument("--work", default="/tmp/exact-flow-blade")
    ap.add_argument("--kmax", type=int, default=8192)
    ap.add_argument("--methods", default="craig-bampton,massless-boundary")
    ap.add_argument("--schemes", default=",".join(s for s, _ in SCHEMES))
    ap.add_argument("--polish", default=None, help="also the CLI's --polish seeded by SCHEME:K (e.g. bds2:256)")
    ap.add_argument("-o", "--output")
    args = ap.parse_args(argv)
    os.makedirs(args.work, exist_ok=True)
    base = localised(open(args.scene).read(), os.path.dirname(os.path.abspath(args.scene)), args.frequency)
    rows, orders, reach, refs = [], [], [], {}
    for method in args.methods.split(","):
        # the exact orbit of the model as exported, from a bds2 answer's contact forces
        text = variant(base, method, "bds2", 256)
        scene = os.path.join(args.work, f"{method}-export.toml")
        open(scene, "w").write(text)
        folder = os.path.join(args.work, f"{method}-model")
        subprocess.run([args.cli, "export", scene, "-o", folder], check=True, capture_output=True)
        guess, _, err = solve(args.cli, args.work, text, f"{method}-guess")
        if guess is None:
            raise SystemExit(f"{method}: the guess solve failed: {err}")
        t0 = time.perf_counter()
        flow = ExactFlow(ContactModel.load(folder))
        y0 = flow.guess_from_forces(guess["time"], np.array([c["force"] for c in guess["contacts"]]))
        orbit = flow.periodic_orbit(y0)
        t_ref = time.perf_counter() - t0
        refs[method] = {"seconds": t_ref, "switches": len(orbit.switches()), "topologies": flow.stats["topologies"],
                        "newton": orbit.history, "n": flow.mdl.n, "m": flow.mdl.m,
                        "peak_to_peak": {k: orbit.peak_to_peak(k) for k in flow.mdl.outputs}}
        print(f"{method}: exact orbit n = {flow.mdl.n}, m = {flow.mdl.m}: {len(orbit.switches())} switches, "
              f"{flow.stats['topologies']} topologies, Newton {len(orbit.history)} its (last {orbit.history[-1]:.1e}), {t_ref:.1f} s",
              flush=True)
        if args.polish:
            ps, pk = args.polish.split(":")
            r, wall, err = solve(args.cli, args.work, variant(base, method, ps, int(pk)), f"{method}-polish", ("--polish",))
            e = compare_with_grid(orbit, r) if r else None
            refs[method]["polish"] = {"wall": wall, "error": e, "message": None if r else err[-300:],
                                      "warnings": r["warnings"] if r else None}
            print(f"  polish ({args.polish}): {wall:.1f} s, " + (f"error {e['max_over_orbit']:.2e}, {r['polish']['status']}: {r['polish'].get('reason', '')}"
                                                          if e else f"failed: {err[-200:]}"), flush=True)
        if args.auto:
            r, wall, err = solve(args.cli, args.work, auto_variant(base, method, TARGET), f"{method}-auto", ok=(0, 2))
            if r is None:
                print(f"  auto     failed: {err[-300:]}", flush=True)
                rows.append({"method": method, "scheme": "auto", "failed": err[-300:]})
            else:
                e = compare_with_grid(orbit, r)
                ch = r.get("scheme_choice", {})
                rows.append({"method": method, "scheme": "auto", "k": ch.get("steps"), "choice": ch, "wall": wall,
                             "solve": r["timing_s"]["total"], "error": e["max_over_orbit"], "error_ptp": e["peak_to_peak"],
                             "error_largest": e["relative_to_largest"]})
                print(f"  auto     picks {ch.get('scheme')} ({ch.get('pairing')}) k = {ch.get('steps')}, "
                      f"met {ch.get('met')}, estimate {ch.get('estimate')}: error {e['max_over_orbit']:.2e} "
                      f"(of the largest output's peak-to-peak {e['relative_to_largest']:.2e}), solve {r['timing_s']['total']:.2f} s, wall {wall:.2f} s",
                      flush=True)
        for scheme, expected in SCHEMES:
            if scheme not in args.schemes.split(","):
                continue
            k = 256
            r, wall, err = solve(args.cli, args.work, variant(base, method, scheme, k), f"{method}-{scheme}-{k}")
            m = re.search(r"steps ≥ (\d+)", err) if r is None else None
            if m:
                k = 1 << int(np.ceil(np.log2(int(m.group(1)))))
                r = None
            errs = []
            if k > args.kmax:
                print(f"  {scheme:8s} needs k >= {k} (stability), above --kmax {args.kmax}", flush=True)
                rows.append({"method": method, "scheme": scheme, "k": k, "failed": f"needs k >= {k}, above --kmax"})
            while k <= args.kmax:
                if r is None:
                    r, wall, err = solve(args.cli, args.work, variant(base, method, scheme, k), f"{method}-{scheme}-{k}")
                if r is None:
                    print(f"  {scheme:8s} k = {k:5d}: failed: {err[-300:]}", flush=True)
                    rows.append({"method": method, "scheme": scheme, "k": k, "failed": err[-300:]})
                    break
                e = compare_with_grid(orbit, r)
                row = {"method": method, "scheme": scheme, "k": k, "N": k * flow.mdl.m, "wall": wall,
                       "solve": r["timing_s"]["total"], "error": e["max_over_orbit"], "error_ptp": e["peak_to_peak"],
                       "error_largest": e["relative_to_largest"], "solver": r["lcp"]["path"]}
                rows.append(row)
                errs.append((k, e["max_over_orbit"]))
                print(f"  {scheme:8s} k = {k:5d}: error {e['max_over_orbit']:.2e} (peak-to-peak {e['peak_to_peak']:.2e}, "
                      f"of the largest output's {e['relative_to_largest']:.2e}), "
                      f"solve {r['timing_s']['total']:.2f} s, wall {wall:.2f} s", flush=True)
                r = None
                if e["max_over_orbit"] <= TARGET and len(errs) >= 3:
                    break
                k *= 2
            hit = next((k for k, e in errs if e <= TARGET), None)
            reach.append({"method": method, "scheme": scheme, "k": hit})
            if len(errs) >= 2:
                (ka, ea), (kb, eb) = errs[-2], errs[-1]
                orders.append({"method": method, "scheme": scheme, "k": [ka, kb], "order": float(np.log2(ea / eb) / np.log2(kb / ka)),
                               "expected": expected})
                print(f"  {scheme:8s} order {orders[-1]['order']:.2f} over k = {ka}-{kb}; reaches 1e-4 at k = {hit}", flush=True)
    if args.output:
        json.dump({"reference": refs, "rows": rows, "orders": orders, "reach": reach}, open(args.output, "w"), indent=1)


if __name__ == "__main__":
    main()
