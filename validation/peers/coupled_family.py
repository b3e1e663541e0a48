"""Coupled normal–tangential friction on a random family, not tuned on: the CLI's LCP against the
event-driven exact orbit of `coupled_exact.py` (issue 25's "coupled normal–tangential contact").

    python coupled_family.py SEED N [k ...]      (from validation/peers, the venv's python)

Each member is the mass on a compliant plane of examples/friction/coupled.toml with parameters
drawn at random: the coupling k_xy, the dampings, the plane's stiffness k_c, μ, the pressing load
N0 + N1 cos Ωt (lift-off when N1 > N0), the tangential drive and Ω. Members whose static wedging
κ = μ·|G_nt|/G_nn (`coupled_exact.wedging`) is ≥ 1 may jam: there the LCP can have no solution,
and the CLI must refuse with a typed diagnosis rather than answer. Prints per member the errors
max_j |x_k(t_j) − x(t_j)| / max|x| (and y, λ) at each k and the observed order.
"""
from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile

import numpy as np

try:
    from .coupled_exact import BINARY, CoupledSystem, solve, solve_from, wedging
except ImportError:  # run as a script from validation/peers
    from coupled_exact import BINARY, CoupledSystem, solve, solve_from, wedging


def draw(rng: np.random.Generator) -> CoupledSystem:
    kx, ky = rng.uniform(0.5, 2.0, 2)
    kxy = rng.uniform(-0.6, 0.6) * np.sqrt(kx * ky)   # |k_xy| < √(k_x k_y): K positive definite
    n0 = rng.uniform(0.5, 1.5)
    return CoupledSystem(
        mass=(1.0, 1.0),
        K=np.array([[kx, kxy], [kxy, ky]]),
        C=np.diag([rng.uniform(0.02, 0.3), rng.uniform(0.1, 1.0)]),
        plane=rng.uniform(2.0, 30.0),
        mu=rng.uniform(0.1, 0.8),
        F0=np.array([0.0, -n0]),
        Fc=np.array([0.0, -n0 * rng.uniform(0.0, 1.6)]),
        Fs=np.array([rng.uniform(0.2, 1.0), 0.0]),
        omega=rng.uniform(0.6, 2.5),
    )


def scene(s: CoupledSystem, k: int) -> str:
    (kx, kxy), (_, ky) = s.K
    return f"""[structure]
mass = [[{float(s.mass[0])!r}, 0.0], [0.0, {float(s.mass[1])!r}]]
stiffness = [[{float(kx)!r}, {float(kxy)!r}], [{float(kxy)!r}, {float(ky)!r}]]
[damping]
matrix = [[{float(s.C[0, 0])!r}, 0.0], [0.0, {float(s.C[1, 1])!r}]]
[excitation]
frequency = {float(s.omega)!r}
[[force]]
dof = 1
amplitude = {float(s.F0[1])!r}
harmonic = 0
[[force]]
dof = 1
amplitude = {float(s.Fc[1])!r}
[[force]]
dof = 0
amplitude = {float(s.Fs[0])!r}
phase = -1.5707963267948966
[[contact]]
dof = 1
direction = -1
gap = 0.0
stiffness = {float(s.plane)!r}
[[friction]]
dof = 0
coefficient = {float(s.mu)!r}
contact = 0
[discretization]
scheme = "bds1"
steps = {k}
[output]
displacement = [0, 1]
"""


def cli(s: CoupledSystem, k: int, binary: str):
    """The CLI's result JSON at k, or (None, its error message) when it refuses."""
    with tempfile.TemporaryDirectory() as d:
        toml, out = os.path.join(d, "scene.toml"), os.path.join(d, "r.json")
        open(toml, "w").write(scene(s, k))
        p = subprocess.run([binary, "solve", toml, "--no-estimate", "-o", out], capture_output=True, text=True)
        if p.returncode != 0:
            return None, (p.stderr.strip().splitlines() or ["(no message)"])[-1]
        return json.load(open(out)), None


def errors(orbit, r, k: int, held: bool, s: CoupledSystem = None):
    """Relative errors of x, y, λ. `held`: stuck all period, so x is any constant its friction
    holds (a family of orbits, one per offset, y and λ loaded by it through k_xy): the reference
    is then the exact orbit marched from the CLI's x (its mean) and y at t = 0, at rest in x."""
    got = [np.array(r["displacement"]["0"]), np.array(r["displacement"]["1"]), np.array(r["contacts"][0]["force"])]
    if held:
        h = orbit.period / k
        orbit = solve_from(s, [got[0].mean(), got[1][0]], [0.0, (got[1][0] - got[1][-1]) / h])
        if {name for _, name in orbit.events()} - {"stick"}:
            print(f"  (k = {k}: marched from the CLI's offset, the exact flows leave the stick: {orbit.events()})")
    ex = orbit.samples(np.arange(k) * orbit.period / k)
    ref = [ex[:, 0], ex[:, 1], ex[:, 2]]
    scale = [max(np.abs(ex[:, i]).max(), 1e-300) for i in range(3)]
    return [np.abs(a - b).max() / c for a, b, c in zip(got, ref, scale)]


def main():
    seed, n = int(sys.argv[1]), int(sys.argv[2])
    steps = [int(v) for v in sys.argv[3:]] or [256, 512, 1024]
    binary = os.environ.get("PC_CLI", BINARY)
    rng = np.random.default_rng(seed)
    rows = []
    for i in range(n):
        s = draw(rng)
        kappa = wedging(s)
        head = (f"member {i:2}: k_xy {s.K[0, 1]:+.3f} k_c {s.plane:5.2f} μ {s.mu:.3f} N0 {-s.F0[1]:.3f} "
                f"N1 {-s.Fc[1]:.3f} drive {s.Fs[0]:.3f} Ω {s.omega:.3f} κ {kappa:.3f}")
        try:
            orbit = solve(s)
        except RuntimeError as e:
            print(f"{head}: reference failed ({e})", flush=True)
            continue
        names = [name for _, name in orbit.events()]
        held = set(names) <= {"stick"}
        errs, refusals = [], []
        for k in steps:
            r, why = cli(s, k, binary)
            if r is None:
                refusals.append(f"k = {k}: {why}")
            else:
                errs.append((k, errors(orbit, r, k, held, s)))
        line = f"{head}: {len(names)} events{' (stuck all period: against the exact orbit at the CLI offset)' if held else ''} ({', '.join(sorted(set(names))) or 'none'})"
        for k, e in errs:
            line += f"; k = {k}: x {e[0]:.2e} y {e[1]:.2e} λ {e[2]:.2e}"
        if len(errs) >= 2:
            (k1, e1), (k2, e2) = errs[-2], errs[-1]
            order = np.log(max(e1) / max(e2)) / np.log(k2 / k1)
            line += f"; order {order:.2f}"
        for why in refusals:
            line += f"; REFUSED {why}"
        print(line, flush=True)
        rows.append((kappa, errs, refusals))
    for k in steps:
        got = [dict(e)[k] for _, e, _ in rows if k in dict(e)]
        if got:
            worst = max(max(v) for v in got)
            print(f"k = {k}: {len(got)} of {len(rows)} answered, worst error {worst:.3e}")
        else:
            print(f"k = {k}: none answered")
    refused = [(kappa, why) for kappa, _, whys in rows for why in whys]
    for kappa, why in refused:
        print(f"refused (κ {kappa:.3f}): {why[:160]}")

if __name__ == "__main__":
    main()
