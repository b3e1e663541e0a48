"""Friction side by side (issue 25), quick form of validation/peers/friction_peer.py: the Jenkins
damper (Ω = 0.9) and the 2-DOF chain with rigid Coulomb on one mass (Ω = 1.2), each against the
Python event-driven exact simulation (validation/peers/friction_exact.py), which is itself checked
against Den Hartog's closed form. Asserted: the polish within 1e-8 of the exact orbit, the plain
LCP converging at first order, harmonic balance (AFT + DLFT) converging to the exact orbit as H
grows. A few seconds.
"""
from __future__ import annotations

import os

import numpy as np
import pytest

from peers import friction_exact, friction_peer


def den_hartog(slip: float, omega: float) -> float:
    """Den Hartog (1931): X of x'' + x = cos Ωt − F sgn ẋ in continuous motion (m = k = 1)."""
    r = 1 / (1 - omega**2)
    s = slip / omega * np.tan(np.pi / (2 * omega))
    return float(np.sqrt(r * r - s * s))


@pytest.mark.parametrize("omega,slip", [(0.6, 0.3), (1.7, 0.2)])
def test_exact_simulation_meets_den_hartog(omega, slip):
    s = friction_exact.FrictionSystem(np.eye(1), np.zeros((1, 1)), np.eye(1), np.array([1.0]), omega, 0, slip)
    orbit = friction_exact.solve(s)
    exact = den_hartog(slip, omega)
    err = abs(orbit.amplitude()[0] - exact) / exact
    print(f"Ω {omega}, μN {slip}: amplitude {orbit.amplitude()[0]:.15f}, Den Hartog {exact:.15f}, error {err:.1e}")
    assert err < 1e-12
    assert orbit.stuck_fraction() == 0.0 and len(orbit.events()) == 2


@pytest.mark.engine
@pytest.mark.parametrize("name,omega", [("damper", 0.9), ("chain", 1.2)])
def test_side_by_side(cli, monkeypatch, tmp_path, name, omega):
    monkeypatch.setenv("PC_CLI", cli)
    case = friction_peer.CASES[name][0]
    r = friction_peer.compare(name, case, omega, str(tmp_path), lcp_steps=[128, 256], polish_steps=[64], ladder=[1, 3, 7, 15, 31])
    lcp, pol, hb = r["lcp"], r["polish"], r["hb"]
    lcp_errors = ", ".join(f"k {x['steps']}: {x['error']:.2e}" for x in lcp)
    hb_errors = ", ".join(f"H {x['H']}: {x['error']:.2e}" if x["converged"] else f"H {x['H']}: failed" for x in hb)
    print(f"{name} Ω {omega}: LCP {lcp_errors}; polish {pol[0]['error']:.1e} ({pol[0]['status']}); HB {hb_errors}")
    assert pol[0]["status"] == "polished" and pol[0]["error"] < 1e-8
    ratio = lcp[0]["error"] / lcp[1]["error"]
    assert 1.6 < ratio < 2.4, f"bds1 is first order: error ratio {ratio:.2f} at k = 128 → 256"
    errors = [x["error"] for x in hb if x["converged"]]
    assert len(errors) >= 4, "HB converged at most H"
    assert errors[-1] < errors[0] / 4, f"HB converges as H grows: {errors}"
    assert errors[-1] < (1e-3 if name == "damper" else 3e-2)


@pytest.mark.engine
def test_chain_sweep_polish_meets_the_exact_simulation(cli, monkeypatch, tmp_path):
    """The chain across both modes (0.77, 1.85 rad/s), k = 512: the plain LCP and the polish
    against the exact simulation per point. Default 4 points in [0.35, 2.3] (~4 s);
    PC_FRICTION_SWEEP=40 runs the record's 40 points (validation/RECORD.md "Friction") in [0.3, 2.6] (~1 min).
    Asserted: the polish succeeds within 1e-8 at every point, whatever its events (the 8-event
    orbit at Ω = 0.595, whose short stops the LCP misses, by marching the exact flows; the orbits
    stuck all period near 2.5, compared up to their means)."""
    monkeypatch.setenv("PC_CLI", cli)
    points = int(os.environ.get("PC_FRICTION_SWEEP", "0") or 0)
    omegas = np.linspace(0.3, 2.6, points) if points else np.linspace(0.35, 2.3, 4)
    rows = friction_peer.sweep_chain(len(omegas), 512, str(tmp_path), omegas=omegas)
    for r in sorted(rows, key=lambda r: -r["polish"]["error"]):
        print(f"Ω {r['omega']:.4f}: {r['events']} events, stuck {r['stuck_fraction']:.3f}: LCP {r['lcp']['error']:.2e}, "
              f"polish {r['polish']['error']:.1e} ({r['polish']['status']})")
    for r in rows:
        pol = r["polish"]
        assert r["lcp"]["error"] < 0.3, r
        assert pol["status"] == "polished", r
        assert pol["error"] < 1e-8, r
