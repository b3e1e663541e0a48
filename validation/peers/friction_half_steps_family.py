"""The CLI's default cds/galerkin friction (event-fitted half steps by shooting) against the
event-driven exact orbit (friction_exact.py), on a random family: max_j |x_j − x(t_j)| over the
amplitude at k = 256 / 512 / 1024, the order 512 → 1024, and the CLI's own error estimate at
k = 512 (Richardson at the scheme's order) over the true error.
Usage: python friction_half_steps_family.py SEED DRAWS [kinds, comma-separated, cycled] [scheme],
or python friction_half_steps_family.py member KIND C OMEGA SLIP [scheme] for one member
(needs target/release/periodic-contact; `python` the venv's). PC_POLISH=1 adds the polish's
error at k = 512."""
import json
import os
import subprocess
import sys
import tempfile

import numpy as np

import friction_exact as fe

HERE = os.path.dirname(os.path.abspath(__file__))
CLI = os.path.join(HERE, "..", "..", "target", "release", "periodic-contact")


def scene(s: fe.FrictionSystem, k: int, scheme: str) -> str:
    mat = lambda a: "[" + ", ".join("[" + ", ".join(repr(float(v)) for v in row) + "]" for row in a) + "]"
    forces = "".join(f"[[force]]\ndof = {i}\namplitude = {float(a)!r}\n\n" for i, a in enumerate(s.F) if a != 0.0)
    damping = f"[damping]\nmatrix = {mat(s.C)}\n\n" if np.any(s.C) else ""
    jenkins = f"stiffness = {s.kt!r}\n" if s.kt is not None else ""
    return (f"[structure]\nmass = {mat(s.M)}\nstiffness = {mat(s.K)}\n\n{damping}[excitation]\nfrequency = {s.omega!r}\n\n{forces}"
            f"[[friction]]\ndof = {s.dof}\ncoefficient = 1.0\nnormal_force = {s.slip_force!r}\n{jenkins}\n"
            f"[discretization]\nscheme = \"{scheme}\"\nsteps = {k}\n\n[output]\ndisplacement = {list(range(s.n))}\n")


def run(s, k, scheme, estimate, polish=False):
    with tempfile.TemporaryDirectory() as d:
        path = os.path.join(d, "f.toml")
        open(path, "w").write(scene(s, k, scheme))
        out = os.path.join(d, "r.json")
        args = [CLI, "solve", path, "-o", out] + ([] if estimate else ["--no-estimate"]) + (["--polish"] if polish else [])
        p = subprocess.run(args, capture_output=True, text=True)
        if p.returncode != 0:
            raise RuntimeError(p.stderr.strip().splitlines()[-1])
        return json.load(open(out))


def system(kind, c, om, sl, kt=None):
    if kind == "chain":
        return fe.FrictionSystem(np.eye(2), c * np.eye(2), np.array([[2.0, -1.0], [-1.0, 1.0]]), np.array([0.0, 1.0]), om, 1, sl, kt)
    return fe.FrictionSystem(np.eye(1), c * np.eye(1), np.eye(1), np.array([1.0]), om, 0, sl, kt)


def report(kind, c, om, sl, kt, scheme):
    """One member: its errors at k = 256 / 512 / 1024, order, estimate/true at 512 (printed)."""
    s = system(kind, c, om, sl, kt)
    try:
        orb = fe.solve(s, substeps=2000, march_tol=1e-11, max_periods=20000)
    except Exception as e:  # noqa: BLE001
        print(kind, c, om, sl, "exact failed", e, flush=True)
        return
    A = orb.amplitude()[s.dof]
    errs, info = [], []
    try:
        for k in (256, 512, 1024):
            r = run(s, k, scheme, estimate=(k == 512))
            x = np.array(r["displacement"][str(s.dof)])
            t = np.arange(k) * s.period / k
            errs.append(np.abs(x - orb.displacement(t)[:, s.dof]).max() / A)
            if k == 512:
                # The estimate covers every displacement output: the true error likewise.
                true_abs = max(np.abs(np.array(r["displacement"][str(i)]) - orb.displacement(t)[:, i]).max() for i in range(s.n))
            info.append(r["lcp"]["path"].split("laws after ")[-1].split(" refits")[0] if "refits" in r["lcp"]["path"] else "-")
            if k == 512:
                est = r["accuracy"]["estimate"]
                stuck = np.mean(r["friction"][0]["stuck"])
    except RuntimeError as e:
        print(f"{kind:18s} c={c:.3f} Ω={om:.3f} μN={sl:.3f}: FAILED {e}", flush=True)
        return
    order = np.log2(errs[1] / errs[2])
    # With PC_POLISH set: the stick–slip polish at k = 512, its error at the instants likewise.
    polished = ""
    if os.environ.get("PC_POLISH"):
        r = run(s, 512, scheme, estimate=False, polish=True)
        t = np.arange(512) * s.period / 512
        e = max(np.abs(np.array(r["displacement"][str(i)]) - orb.displacement(t)[:, i]).max() for i in range(s.n)) / orb.amplitude().max()
        polished = f" polish {e:.1e} ({r.get('polish', {}).get('status', '?')})"
    ratio = est / true_abs if est is not None else float("nan")
    print(f"{kind:18s} c={c:.3f} Ω={om:.3f} μN={sl:.3f} stuck={orb.stuck_fraction():.3f} (k = 512: {stuck:.3f}): err {errs[0]:.2e} {errs[1]:.2e} {errs[2]:.2e}"
          f" order(512→1024) {order:.2f} est512/true {ratio:.2f} refits {info}{polished}", flush=True)


if __name__ == "__main__":
    if len(sys.argv) > 1 and sys.argv[1] == "member":
        # One member by its parameters: member KIND C OMEGA SLIP [scheme].
        kind, c, om, sl = sys.argv[2], *map(float, sys.argv[3:6])
        report(kind, c, om, sl, None, sys.argv[6] if len(sys.argv) > 6 else "cds")
        sys.exit(0)
    seed = int(sys.argv[1]) if len(sys.argv) > 1 else 7
    draws = int(sys.argv[2]) if len(sys.argv) > 2 else 8
    kinds = (sys.argv[3] if len(sys.argv) > 3 else "den_hartog_c0,den_hartog_damped,chain").split(",")
    scheme = sys.argv[4] if len(sys.argv) > 4 else "cds"
    rng = np.random.default_rng(seed)
    for i in range(draws):
        kind = kinds[i % len(kinds)]
        c = 0.0 if kind == "den_hartog_c0" else rng.uniform(0.02, 0.2)
        om = rng.uniform(0.5, 2.0) if kind != "chain" else rng.uniform(0.3, 1.6)
        sl = rng.uniform(0.1, 0.9)
        kt = rng.uniform(1.0, 5.0) if kind == "jenkins" else None
        report(kind, c, om, sl, kt, scheme)
