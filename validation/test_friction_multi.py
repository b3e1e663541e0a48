"""Several friction contacts (issue 25): the multi-contact event-driven simulation
(validation/peers/friction_multi_exact.py) reduces to the one-contact one (friction_exact.py, itself
checked against Den Hartog's closed form); the random family of chains through the CLI's polish is
opt-in: PC_FRICTION_MULTI_FAMILY=30 (cases; about 20 min at load 15, mostly the LCPs at k = 512).
"""
from __future__ import annotations

import os

import numpy as np
import pytest

from peers import friction_exact, friction_multi_exact, friction_multi_family


@pytest.mark.parametrize("omega,kt", [(0.8, None), (1.2, 2.0)])
def test_multi_contact_simulation_reduces_to_the_one_contact_one(omega, kt):
    M, C, K = np.diag([1.0, 0.5]), np.array([[0.06, -0.02], [-0.02, 0.02]]), np.array([[2.0, -1.0], [-1.0, 1.0]])
    one = friction_exact.solve(friction_exact.FrictionSystem(M, C, K, np.array([1.0, 0.0]), omega, 1, 0.4, kt))
    multi = friction_multi_exact.steady(friction_multi_exact.System(M, C, K, [1.0, 0.0], omega, [([0.0, 1.0], 0.4, kt)]))
    T = 2 * np.pi / omega
    times = np.arange(64) * T / 64
    a, b = one.displacement(times), np.array([multi.displacement(t) for t in times])
    err = np.abs(a - b).max() / np.abs(a).max()
    print(f"Ω {omega}, k_t {kt}: {len(multi.events)} events, max difference {err:.1e}")
    assert err < 1e-9


@pytest.mark.engine
@pytest.mark.skipif(not os.environ.get("PC_FRICTION_MULTI_FAMILY"), reason="opt-in: PC_FRICTION_MULTI_FAMILY=<cases>")
def test_random_family_polishes_exactly_or_falls_back(cli):
    rows = friction_multi_family.family(int(os.environ["PC_FRICTION_MULTI_FAMILY"]), 2026, cli)
    for err, desc, status, why, _ in rows:
        print(f"{err:.2e} {status} {desc} {why[:160]}")
    # A polished orbit is exact; a fallback says why (the LCP's orbit is kept).
    assert all(err <= 1e-8 for err, _, status, _, _ in rows if status == "polished")
    assert all(why for _, _, status, why, _ in rows if status != "polished")
