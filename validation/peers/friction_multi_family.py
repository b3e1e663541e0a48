"""A random family of chains with several friction contacts (rigid Coulomb and Jenkins), not tuned
on: the CLI's LCP at k = 512 with the stick–slip polish (`solve --polish`) against the exact
event-driven simulation of friction_multi_exact.py. Reports how many polish to 1e-8 (max over the
DOFs and instants of |x − x_exact| / max |x_exact|), worst first, and why the rest fall back.

    PC_CLI=$PWD/target/release/periodic-contact validation/.venv/bin/python \
        validation/peers/friction_multi_family.py [cases] [seed]
"""
from __future__ import annotations

import json
import os
import resource
import subprocess
import sys
import tempfile

import numpy as np

try:
    from peers import friction_multi_exact as fx
except ImportError:  # run as a script from validation/peers
    import friction_multi_exact as fx


def structure(rng):
    """A chain of 2–3 masses: (n, M, C, K, F), forced on the first mass (and the last)."""
    n = int(rng.integers(2, 4))
    m = rng.uniform(0.5, 1.5, n)
    k = rng.uniform(0.5, 2.0, n)  # k[0] to ground, k[i] between i−1 and i
    K = np.zeros((n, n))
    K[0, 0] += k[0]
    for i in range(1, n):
        K[i - 1, i - 1] += k[i]
        K[i, i] += k[i]
        K[i - 1, i] -= k[i]
        K[i, i - 1] -= k[i]
    M = np.diag(m)
    C = rng.uniform(0.01, 0.05) * M + rng.uniform(0.005, 0.03) * K
    F = np.zeros(n)
    F[0] = 1.0
    F[n - 1] += rng.uniform(-0.5, 0.5)
    return n, M, C, K, F


def draw(rng):
    n, M, C, K, F = structure(rng)
    dofs = rng.choice(n, size=int(rng.integers(2, n + 1)), replace=False)
    contacts = []
    for d in sorted(dofs):
        b = np.zeros(n)
        b[d] = 1.0
        kt = float(rng.uniform(1.0, 5.0)) if rng.random() < 0.4 else None
        contacts.append((b, float(rng.uniform(0.05, 0.8)), kt))
    omega = float(rng.uniform(0.3, 2.0))
    return fx.System(M, C, K, F, omega, contacts)


def parts(s):
    """(direction, μN, k_t) per contact."""
    return zip(s.b, s.slip, s.kt)


def scene(s, steps):
    rows = lambda a: "[" + ", ".join("[" + ", ".join(repr(float(v)) for v in r) + "]" for r in a) + "]"  # noqa: E731
    out = f"[structure]\nmass = {rows(s.M)}\nstiffness = {rows(s.K)}\n\n[damping]\nmatrix = {rows(s.C)}\n\n"
    out += f"[excitation]\nfrequency = {s.omega!r}\n\n"
    for d, a in enumerate(s.F):
        if a != 0.0:
            out += f"[[force]]\ndof = {d}\namplitude = {float(a)!r}\n\n"
    for b, slip, kt in parts(s):
        out += f"[[friction]]\ndof = {int(np.argmax(b))}\ncoefficient = 1.0\nnormal_force = {slip!r}\n"
        out += f"stiffness = {kt!r}\n\n" if kt is not None else "\n"
    out += f"[discretization]\nscheme = \"bds1\"\nsteps = {steps}\n\n[output]\ndisplacement = {list(range(s.n))}\n"
    return out


def family(cases, seed, cli):
    """[(error, description, status, reason, CLI CPU s)] per case, worst first."""
    rng = np.random.default_rng(seed)
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for c in range(cases):
            s = draw(rng)
            desc = (f"#{c} n={s.n} Ω={s.omega:.3f} contacts=" +
                    ",".join(f"{int(np.argmax(b))}:{sl:.2f}{'' if kt is None else f'/kt{kt:.2f}'}" for b, sl, kt in parts(s)))
            try:
                ex = fx.steady(s)
            except Exception as e:  # noqa: BLE001
                rows.append((np.inf, desc, "reference failed", str(e), 0.0))
                continue
            if ex.residual > 1e-10:
                rows.append((np.inf, desc, "reference failed", f"shooting residual {ex.residual:.1e}", 0.0))
                continue
            err, status, why, cpu = polish_against(cli, tmp, scene(s, 512), s, ex)
            rows.append((err, desc, status, why, cpu))
            print(f"{desc}: {status}, error {err:.2e}, {why[:160]}", flush=True)
    rows.sort(key=lambda r: -r[0])
    return rows



def polish_against(cli, tmp, text, s, ex):
    """Solves scene `text` with `--polish` by the CLI and compares its displacements at the instants
    with the exact orbit `ex` (over the largest amplitude; up to the means where a slider is stuck
    all period, the force being unique only up to its constant): (error, status, why, CPU s)."""
    path, out = os.path.join(tmp, "s.toml"), os.path.join(tmp, "r.json")
    with open(path, "w") as f:
        f.write(text)
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    p = subprocess.run([cli, "solve", path, "--polish", "--no-estimate", "-o", out], capture_output=True, text=True)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = after.ru_utime - before.ru_utime + after.ru_stime - before.ru_stime
    if p.returncode != 0:
        return np.inf, "cli failed", p.stderr.strip()[:200], cpu
    r = json.load(open(out))
    x = np.array([r["displacement"][str(d)] for d in range(s.n)])
    xe = np.array([ex.displacement(t) for t in r["time"]]).T
    if any(ex.stuck_fraction(i) > 1 - 1e-12 for i in range(s.m)):
        x, xe = x - x.mean(1, keepdims=True), xe - xe.mean(1, keepdims=True)
    err = float(np.abs(x - xe).max() / np.abs(xe).max())
    pol = r.get("polish") or {}
    status = pol.get("status", "?")
    why = pol.get("reason", "") if status != "polished" else f"{len(pol.get('events', []))} events (exact {len(ex.events)})"
    return err, status, why, cpu

def main():
    cases = int(sys.argv[1]) if len(sys.argv) > 1 else 30
    seed = int(sys.argv[2]) if len(sys.argv) > 2 else 2026
    cli = os.environ.get("PC_CLI", os.path.join(os.path.dirname(__file__), "..", "..", "target", "release", "periodic-contact"))
    rows = family(cases, seed, cli)
    ok = sum(1 for r in rows if r[2] == "polished" and r[0] <= 1e-8)
    print(f"\n{ok} of {len(rows)} polished to 1e-8 at k = 512 (seed {seed}); worst first:")
    for err, desc, status, why, cpu in rows:
        print(f"  {err:.2e}  {status:9s} {desc}  [{cpu:.2f} s CPU]  {why[:200]}")


if __name__ == "__main__":
    main()
