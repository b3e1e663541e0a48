"""Coupled normal–tangential friction (issue 25): the exact event-driven reference
(validation/peers/coupled_exact.py) checked against Den Hartog's closed form where the coupling
vanishes, and the CLI's LCP on examples/friction/coupled.toml converging to its exact orbit at
first order. About a second.
"""
from __future__ import annotations

import numpy as np
import pytest

from peers import coupled_exact as ce
from test_friction_peer import den_hartog


@pytest.mark.parametrize("omega,slip", [(0.6, 0.3), (1.7, 0.2)])
def test_uncoupled_reference_meets_den_hartog(omega, slip):
    # k_xy = 0 and a constant normal load N0: the plane's static force is λ = k_c N0/(k_y + k_c),
    # so μλ = slip with N0 = (1 + k_c)/k_c and μ = slip; x'' + x = cos Ωt − μλ sgn ẋ (c_x = 0).
    kc = 10.0
    s = ce.CoupledSystem(K=np.eye(2), C=np.diag([0.0, 0.8]), plane=kc, mu=slip, F0=np.array([0.0, -(1 + kc) / kc]),
                         Fc=np.array([1.0, 0.0]), Fs=np.zeros(2), omega=omega)
    orbit = ce.solve(s)
    # Continuous motion: the reversals (slip ends at ẋ = 0) are the extremes of x.
    ends = [y[0] for _, phase, y in orbit.segments[1:] if phase in (ce.SLIP_UP, ce.SLIP_DOWN)]
    amplitude = 0.5 * (max(ends) - min(ends))
    exact = den_hartog(slip, omega)
    err = abs(amplitude - exact) / exact
    print(f"Ω {omega}, μλ {slip}: amplitude {amplitude:.15f}, Den Hartog {exact:.15f}, error {err:.1e}")
    assert err < 1e-10
    assert [name for _, name in orbit.events()].count("stick") == 0
    assert all(p != ce.FREE for _, p, _ in orbit.segments)


@pytest.mark.engine
def test_cli_converges_to_the_exact_coupled_orbit(cli):
    orbit = ce.solve(ce.example())
    rows = ce.cli_errors(orbit, steps=(128, 256), binary=cli)
    (_, (e1, _), _, _), (_, (e2, _), _, _) = rows
    print("errors (x, y, λ_n) at k = 128:", e1, "k = 256:", e2)
    for a, b in zip(e1, e2):
        assert b < a and 0.8 < np.log2(a / b) < 1.3
    assert e2[0] < 0.1 and e2[1] < 0.04
