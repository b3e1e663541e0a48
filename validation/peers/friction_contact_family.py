"""A random family of chains with friction contacts (rigid Coulomb and Jenkins, constant normal
loads) AND one compliant unilateral stop, not tuned on: the CLI's LCP at k = 512 with the
stick–slip polish (`solve --polish`) against the exact event-driven simulation of
friction_contact_exact.py. Reports how many polish to 1e-8 (max over the DOFs and instants of
|x − x_exact| / max |x_exact|), worst first, and why the rest fall back.

    PC_CLI=$PWD/target/release/periodic-contact validation/.venv/bin/python \
        validation/peers/friction_contact_family.py [cases] [seed]

Draws: 2–3 masses (m ∈ [0.5, 1.5], springs ∈ [0.5, 2], Rayleigh damping), 1–2 friction contacts
on distinct masses (40 % Jenkins, k_t ∈ [1, 5]), μN ∈ [0.05, 0.8], Ω ∈ [0.3, 2]; one stop on a
random mass and side, k_c ∈ [1, 20], its gap a fraction ∈ [0.1, 0.8] of that mass's amplitude
without friction and stop (so that most stops close; those that never do are counted).
"""
from __future__ import annotations

import os
import sys
import tempfile

import numpy as np

try:
    from peers import friction_contact_exact as fc
    from peers import friction_multi_exact as fx
    from peers import friction_multi_family as fm
except ImportError:  # run as a script from validation/peers
    import friction_contact_exact as fc
    import friction_multi_exact as fx
    import friction_multi_family as fm


def draw(rng):
    n, M, C, K, F = fm.structure(rng)
    omega = float(rng.uniform(0.3, 2.0))
    contacts = []
    for d in sorted(rng.choice(n, size=int(rng.integers(1, 3)), replace=False)):
        b = np.zeros(n)
        b[d] = 1.0
        kt = float(rng.uniform(1.0, 5.0)) if rng.random() < 0.4 else None
        contacts.append((b, float(rng.uniform(0.05, 0.8)), kt))
    d = int(rng.integers(0, n))
    side = 1.0 if rng.random() < 0.5 else -1.0
    amp = np.abs(np.linalg.solve(K - omega**2 * M + 1j * omega * C, F))[d]
    c = np.zeros(n)
    c[d] = side
    stop = (c, float(rng.uniform(0.1, 0.8) * amp), float(rng.uniform(1.0, 20.0)))
    return fc.ContactSystem(M, C, K, F, omega, contacts, [stop])


def scene(s, steps):
    out = fm.scene(s, steps)
    head, tail = out.split("[discretization]")
    for c, g, k in s.stops:
        d = int(np.argmax(np.abs(c)))
        head += f"[[contact]]\ndof = {d}\ndirection = {int(c[d])}\ngap = {g!r}\nstiffness = {k!r}\n\n"
    return head + "[discretization]" + tail


def describe(c, s):
    fr = ",".join(f"{int(np.argmax(b))}:{sl:.2f}{'' if kt is None else f'/kt{kt:.2f}'}" for b, sl, kt in fm.parts(s))
    st = ",".join(f"{int(np.argmax(np.abs(cc)))}{'+' if cc.sum() > 0 else '-'}:g{g:.3f}/kc{k:.1f}" for cc, g, k in s.stops)
    return f"#{c} n={s.n} Ω={s.omega:.3f} friction={fr} stop={st}"


def family(cases, seed, cli):
    """[(error, description, status, reason, CLI CPU s, stop events of the reference)], worst first."""
    rng = np.random.default_rng(seed)
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for c in range(cases):
            s = draw(rng)
            desc = describe(c, s)
            try:
                ex = fx.steady(s)
            except Exception as e:  # noqa: BLE001
                rows.append((np.inf, desc, "reference failed", str(e), 0.0, 0))
                continue
            touches = sum(1 for e in ex.events if e[1] >= s.m)
            if ex.residual > 1e-10:
                rows.append((np.inf, desc, "reference failed", f"shooting residual {ex.residual:.1e}", 0.0, touches))
                continue
            err, status, why, cpu = fm.polish_against(cli, tmp, scene(s, 512), s, ex)
            rows.append((err, desc, status, why, cpu, touches))
            print(f"{desc}: {status}, error {err:.2e}, stop events {touches}, {why[:160]}", flush=True)
    rows.sort(key=lambda r: -r[0])
    return rows


def main():
    cases = int(sys.argv[1]) if len(sys.argv) > 1 else 20
    seed = int(sys.argv[2]) if len(sys.argv) > 2 else 2027
    cli = os.environ.get("PC_CLI", os.path.join(os.path.dirname(__file__), "..", "..", "target", "release", "periodic-contact"))
    rows = family(cases, seed, cli)
    ok = sum(1 for r in rows if r[2] == "polished" and r[0] <= 1e-8)
    closing = sum(1 for r in rows if r[5] > 0)
    print(f"\n{ok} of {len(rows)} polished to 1e-8 at k = 512 (seed {seed}; the stop closes in {closing}); worst first:")
    for err, desc, status, why, cpu, touches in rows:
        print(f"  {err:.2e}  {status:9s} {desc}  stop events {touches}  [{cpu:.2f} s CPU]  {why[:200]}")


if __name__ == "__main__":
    main()
