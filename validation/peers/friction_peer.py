"""Friction side by side (issue 25): our periodic LCP (bds1 at k instants), its stick–slip polish
(`--polish`) and a harmonic-balance peer (AFT + DLFT, validation/peers/friction_hb.py) against the
exact event-driven simulation (validation/peers/friction_exact.py, Python, independent of the
crate), in one run, on

- `damper`: the Jenkins damper of fmu/scenes/friction-damper.toml (m = k = 1, c = 0.1, P = 1,
  μN = 0.5, k_t = 2) at several frequencies across its resonance;
- `chain`: ground–k1–m1–k2–m2 (m = 1, 0.5; k = 1, 1; the load on m1), rigid Coulomb on m2
  (μN = 0.25): the chain of tests/friction.rs, modes 0.77 and 1.85 rad/s.

The error of a method is max_j |x(t_j) − x_ex(t_j)| over every DOF and its output instants (the
LCP's k instants; HB at 512 uniform times), divided by the largest exact amplitude (half peak to
peak); up to each DOF's mean where the exact orbit is stuck for the whole period (its position is
then not unique). CPU: the CLI process's user+system time (getrusage of the child: start-up, scene parse,
solve, JSON write); HB's time.process_time() over its H ladder 1, 3, 7, … (each solve seeded by
the previous one, as HB is used). `--sweep P` adds the chain over P frequencies in [0.3, 2.6]:
the plain LCP at k = `--sweep-steps` and the polish, against the exact simulation per point;
`--sweep-seed S` sweeps a chain drawn from seed S instead (masses, springs, dampers, μN).

    PC_CLI=target/release/periodic-contact validation/.venv/bin/python validation/peers/friction_peer.py \
        [--sweep 40] [--sweep-seed S] [--out validation/peers/out]
"""
from __future__ import annotations

import argparse
import json
import os
import resource
import subprocess
import sys
import tempfile
import time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
from peers import friction_exact, friction_hb  # noqa: E402

DAMPER = dict(M=[[1.0]], C=[[0.1]], K=[[1.0]], F=[1.0], dof=0, slip=0.5, kt=2.0)
CHAIN = dict(M=[[1.0, 0.0], [0.0, 0.5]], C=[[0.06, -0.02], [-0.02, 0.02]], K=[[2.0, -1.0], [-1.0, 1.0]],
             F=[1.0, 0.0], dof=1, slip=0.25, kt=None)
CASES = {"damper": (DAMPER, [0.6, 0.9, 1.1, 1.4, 1.8]), "chain": (CHAIN, [0.4, 0.8, 1.2, 1.85, 2.4])}
LCP_STEPS = [64, 128, 256, 512, 1024, 2048]      # N = 2k ≤ 4096 (FRICTION_DENSE_MAX)
POLISH_STEPS = [32, 64, 128, 256]
HB_LADDER = [1, 3, 7, 15, 31, 63, 127]
TARGETS = [1e-3, 1e-6]


def system(case: dict, omega: float) -> friction_exact.FrictionSystem:
    a = {k: np.array(case[k], dtype=float) for k in ("M", "C", "K", "F")}
    return friction_exact.FrictionSystem(a["M"], a["C"], a["K"], a["F"], omega, case["dof"], case["slip"], case["kt"])


def scene(case: dict, omega: float, steps: int) -> str:
    n = len(case["M"])
    forces = "".join(f"[[force]]\ndof = {d}\namplitude = {f!r}\n\n" for d, f in enumerate(case["F"]) if f)
    jenkins = f"stiffness = {case['kt']!r}\n" if case["kt"] else ""
    return (f"[structure]\nmass = {case['M']}\nstiffness = {case['K']}\n\n[damping]\nmatrix = {case['C']}\n\n"
            f"[excitation]\nfrequency = {omega!r}\n\n{forces}"
            f"[[friction]]\ndof = {case['dof']}\ncoefficient = 1.0\nnormal_force = {case['slip']!r}\n{jenkins}\n"
            f"[discretization]\nscheme = \"bds1\"\nsteps = {steps}\n\n[output]\ndisplacement = {list(range(n))}\n")


def cli_path() -> str:
    here = os.path.dirname(os.path.abspath(__file__))
    return os.environ.get("PC_CLI", os.path.join(here, "..", "..", "target", "release", "periodic-contact"))


def run_cli(case, omega, steps, polish, workdir):
    """Our solve: (result JSON, child CPU seconds)."""
    path = os.path.join(workdir, "scene.toml")
    out = os.path.join(workdir, "result.json")
    with open(path, "w") as f:
        f.write(scene(case, omega, steps))
    args = [cli_path(), "solve", path, "--no-estimate", "-o", out] + (["--polish"] if polish else [])
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    proc = subprocess.run(args, capture_output=True, text=True)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if proc.returncode != 0:
        raise RuntimeError(f"{' '.join(args)} failed: {proc.stderr.strip()}")
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    with open(out) as f:
        return json.load(f), cpu


def orbit_error(exact, times, x, scale) -> float:
    """max over times and DOFs of |x − x_exact| / scale. A contact stuck for the whole period
    leaves its DOF's position free (any constant the holding force allows; the slip velocity is
    unique, formulation.md §9): then both orbits are compared up to their means."""
    x, xe = np.asarray(x, dtype=float), exact.displacement(times)
    if not exact.events() and exact.segments[0][1] == friction_exact.STICK:
        x, xe = x - x.mean(axis=0), xe - xe.mean(axis=0)
    return float(np.abs(x - xe).max() / scale)


def ours(case, omega, exact, scale, steps, polish, workdir):
    r, cpu = run_cli(case, omega, steps, polish, workdir)
    n = len(case["M"])
    x = np.array([r["displacement"][str(d)] for d in range(n)]).T
    row = {"steps": steps, "cpu_s": cpu, "error": orbit_error(exact, r["time"], x, scale),
           "amplitude_error": float(np.abs(0.5 * (x.max(0) - x.min(0)) - exact.amplitude()).max() / scale)}
    if polish:
        p = r.get("polish") or {}
        row["status"] = p.get("status")
        row["reason"] = p.get("reason", "")
    return row


def harmonic_balance(case, omega, exact, scale, ladder):
    s = system(case, omega)
    rows, guess, cpu = [], None, 0.0
    times = np.arange(512) * s.period / 512
    for H in ladder:
        t = time.process_time()
        sol = friction_hb.solve(s.M, s.C, s.K, s.F, omega, s.dof, s.slip_force, s.kt, H, guess=guess)
        if not (sol.converged and sol.residual < 1e-8) and guess is not None:
            # hybrd stalled from the previous H's root: retry from the stuck seed (time counted).
            sol = friction_hb.solve(s.M, s.C, s.K, s.F, omega, s.dof, s.slip_force, s.kt, H)
        cpu += time.process_time() - t
        row = {"H": H, "N": sol.N, "cpu_s": cpu, "converged": bool(sol.converged and sol.residual < 1e-8),
               "residual": sol.residual, "evaluations": sol.evaluations}
        if row["converged"]:
            guess = sol.W
            row["error"] = orbit_error(exact, times, sol.displacement(times), scale)
            row["amplitude_error"] = float(np.abs(sol.amplitude() - exact.amplitude()).max() / scale)
        rows.append(row)
    return rows


def cost_at(rows, target, key="error"):
    """The least CPU time among the runs within `target`, or None."""
    ok = [r["cpu_s"] for r in rows if r.get(key) is not None and r[key] <= target and r.get("converged", True)]
    return min(ok) if ok else None


def exact_orbit(case, omega):
    t = time.process_time()
    orbit = friction_exact.solve(system(case, omega))
    return orbit, time.process_time() - t


def compare(name, case, omega, workdir, lcp_steps=LCP_STEPS, polish_steps=POLISH_STEPS, ladder=HB_LADDER):
    exact, exact_cpu = exact_orbit(case, omega)
    amplitude = exact.amplitude()
    scale = float(amplitude.max())
    lcp = [ours(case, omega, exact, scale, k, False, workdir) for k in lcp_steps]
    pol = [ours(case, omega, exact, scale, k, True, workdir) for k in polish_steps]
    for r in pol:
        r["converged"] = r["status"] == "polished"
    hb = harmonic_balance(case, omega, exact, scale, ladder)
    return {"case": name, "omega": omega, "amplitude": amplitude.tolist(), "stuck_fraction": exact.stuck_fraction(),
            "events": len(exact.events()), "exact_cpu_s": exact_cpu, "lcp": lcp, "polish": pol, "hb": hb}


def fmt_cost(rows, target):
    c = cost_at(rows, target)
    if c is not None:
        return f"{c:.3f} s"
    best = min((r for r in rows if r.get("error") is not None and r.get("converged", True)), key=lambda r: r["error"], default=None)
    return "not reached" + (f" (best {best['error']:.1e} at {best['cpu_s']:.2f} s)" if best else "")


def report(results, sweep):
    lines = [f"# Friction side by side (load: {os.getloadavg()[0]:.1f})", ""]
    for name in CASES:
        rows = sorted((r for r in results if r["case"] == name), key=lambda r: -r["lcp"][-1]["error"])
        lines += [f"## {name} (worst plain LCP first)", "",
                  "| Ω | amplitude | stuck | LCP k: error | polish k: error (status) | HB H: error | CPU at 1e-3: LCP / polish / HB | CPU at 1e-6: LCP / polish / HB |",
                  "|---|---|---|---|---|---|---|---|"]
        for r in rows:
            lcp = ", ".join(f"{x['steps']}: {x['error']:.1e}" for x in r["lcp"])
            pol = ", ".join(f"{x['steps']}: {x['error']:.1e}" + ("" if x["converged"] else f" ({x['status']})") for x in r["polish"])
            hb = ", ".join(f"{x['H']}: {x['error']:.1e}" if x["converged"] else f"{x['H']}: failed" for x in r["hb"])
            costs = [" / ".join(fmt_cost(r[m], t) for m in ("lcp", "polish", "hb")) for t in TARGETS]
            amp = ", ".join(f"{a:.4g}" for a in r["amplitude"])
            lines.append(f"| {r['omega']} | {amp} | {r['stuck_fraction']:.3f} | {lcp} | {pol} | {hb} | {costs[0]} | {costs[1]} |")
        lines.append("")
    if sweep:
        lines += ["## chain sweep (worst polish first)", "", "| Ω | amplitude | stuck | events | LCP error | polish error (status) |", "|---|---|---|---|---|---|"]
        for r in sorted(sweep, key=lambda r: -r["polish"]["error"]):
            amp = ", ".join(f"{a:.4g}" for a in r["amplitude"])
            st = r["polish"]["status"] + (f": {r['polish']['reason']}" if r["polish"]["reason"] else "")
            lines.append(f"| {r['omega']:.4f} | {amp} | {r['stuck_fraction']:.3f} | {r['events']} | {r['lcp']['error']:.2e} | {r['polish']['error']:.2e} ({st}) |")
        worst_lcp = max(r["lcp"]["error"] for r in sweep)
        polished = [r for r in sweep if r["polish"]["status"] == "polished"]
        worst_pol = max((r["polish"]["error"] for r in polished), default=float("nan"))
        lines += ["", f"{len(sweep)} points: worst plain LCP error {worst_lcp:.2e}; polished at {len(polished)}, worst polish error {worst_pol:.2e}"]
    return "\n".join(lines) + "\n"


def random_chain(seed: int) -> tuple[dict, tuple[float, float]]:
    """A chain drawn from `seed` (the "did not tune on" check): masses and springs in [0.5, 2],
    dampers in [0.01, 0.08], μN in [0.1, 0.5] on m2, the load 1 on m1; the sweep range runs from
    0.4·ω1 to 1.4·ω2 (the linear chain's modes with m2 free)."""
    rng = np.random.default_rng(seed)
    m1, m2, k1, k2 = rng.uniform(0.5, 2.0, 4)
    c1, c2 = rng.uniform(0.01, 0.08, 2)
    slip = float(rng.uniform(0.1, 0.5))
    M, K = np.diag([m1, m2]), np.array([[k1 + k2, -k2], [-k2, k2]])
    C = np.array([[c1 + c2, -c2], [-c2, c2]])
    w = np.sqrt(np.sort(np.linalg.eigvals(np.linalg.solve(M, K)).real))
    case = dict(M=M.tolist(), C=C.tolist(), K=K.tolist(), F=[1.0, 0.0], dof=1, slip=slip, kt=None)
    return case, (0.4 * float(w[0]), 1.4 * float(w[1]))


def sweep_chain(points, steps, workdir, omegas=None, case=CHAIN, span=(0.3, 2.6)):
    rows = []
    for omega in np.linspace(*span, points) if omegas is None else omegas:
        omega = float(omega)
        exact, cpu = exact_orbit(case, omega)
        scale = float(exact.amplitude().max())
        lcp = ours(case, omega, exact, scale, steps, False, workdir)
        pol = ours(case, omega, exact, scale, steps, True, workdir)
        rows.append({"omega": omega, "amplitude": exact.amplitude().tolist(), "stuck_fraction": exact.stuck_fraction(),
                     "events": len(exact.events()), "exact_cpu_s": cpu, "lcp": lcp, "polish": pol})
        print(f"sweep Ω {omega:.4f}: LCP {lcp['error']:.2e}, polish {pol['error']:.2e} ({pol['status']})", flush=True)
    return rows


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--sweep", type=int, default=0, help="chain sweep points (0: none)")
    ap.add_argument("--sweep-steps", type=int, default=512)
    ap.add_argument("--sweep-seed", type=int, default=None, help="sweep a random chain drawn from this seed instead")
    ap.add_argument("--cases", default="damper,chain")
    ap.add_argument("--out", default=os.path.join(os.path.dirname(os.path.abspath(__file__)), "out"))
    a = ap.parse_args(argv)
    os.makedirs(a.out, exist_ok=True)
    results = []
    with tempfile.TemporaryDirectory() as work:
        for name in [c for c in a.cases.split(",") if c]:
            case, omegas = CASES[name]
            for omega in omegas:
                results.append(compare(name, case, omega, work))
                print(f"{name} Ω {omega}: done", flush=True)
        case, span = (CHAIN, (0.3, 2.6)) if a.sweep_seed is None else random_chain(a.sweep_seed)
        sweep = sweep_chain(a.sweep, a.sweep_steps, work, case=case, span=span) if a.sweep else []
    text = report(results, sweep)
    if a.sweep and a.sweep_seed is not None:
        text += f"\nrandom chain (seed {a.sweep_seed}): {json.dumps(case)}, Ω ∈ [{span[0]:.4f}, {span[1]:.4f}]\n"
    with open(os.path.join(a.out, "friction_peer.md"), "w") as f:
        f.write(text)
    with open(os.path.join(a.out, "friction_peer.json"), "w") as f:
        json.dump({"results": results, "sweep": sweep}, f, indent=1)
    print(text)


if __name__ == "__main__":
    main()
