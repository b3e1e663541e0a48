"""The exact references (marching/exact.py) reproduce the numbers of src/formulation.md §6."""
import numpy as np
import pytest

from marching.exact import (LinearFlow, compliant_stop, linear_discrete, linear_response, rigid_stop_impacting,
                            rigid_stop_sticking)
from marching.model import Force, System


def test_flow_closed_form_matches_expm():
    """The vectorised eigen-decomposition flow equals scipy.linalg.expm (both phases)."""
    for fl in (LinearFlow(1, 0.05, 1, 1, 1.3), LinearFlow(1, 0.05, 11, 1, 1.3, 10.0)):
        for t in (0.3, 2.0, 7.5):
            np.testing.assert_allclose(fl(t, 0.1, (0.3, -0.2)), fl.expm_state(t, 0.1, (0.3, -0.2)), rtol=1e-12, atol=1e-13)


def test_compliant_stop_notes_numbers():
    """Notes §6.2: t0/T = 0.9389205916, t1/T = 1.1343892296, v0 = 4.460827031 (10 digits)."""
    o = compliant_stop(1, 0.05, 1, 10, 1, 1, 1.3)
    assert abs(o.t0 / o.T - 0.9389205916) < 1e-10
    assert abs(o.t1 / o.T - 1.1343892296) < 1e-10
    assert abs(o.v0 - 4.460827031) < 1e-9
    assert np.max(np.abs(o.residual())) < 1e-12
    # the orbit closes: state after one period equals the state at t0
    y0 = o.state([o.t0 + 1e-9])[:, 0]
    y1 = o.state([o.t0 + o.T + 1e-9])[:, 0]
    np.testing.assert_allclose(y0, y1, atol=1e-10)


def test_compliant_stop_from_explicit_guess():
    """Newton from a guess 2% off lands on the same orbit (no dependence on the internal seed)."""
    o = compliant_stop(1, 0.05, 1, 10, 1, 1, 1.3, guess=(0.95 * 4.8332, 1.15 * 4.8332, 4.5))
    assert abs(o.t0 / o.T - 0.9389205916) < 1e-10


def test_rigid_stop_sticking_notes_numbers():
    """Notes §6.3: min x = -1.869854, impulse per period 2.80804."""
    r = rigid_stop_sticking(1, 0.1, 1, 1, 0.5, 1)
    assert abs(r.min_x() - (-1.869854)) < 1e-6
    assert abs(r.impulse - 2.80804) < 1e-5
    assert abs(r.td - np.pi / 3) < 1e-15            # arccos(k g0 / F) = π/3
    # impulse = impact (m v-) + sticking (∫ F cos Ωt - k g0)
    assert abs(r.impact_impulse + r.stick_impulse - r.impulse) < 1e-15
    assert r.stick_impulse > 0 and r.impact_impulse > 0


def test_rigid_stop_impacting_closes():
    """No sticking (F <= k g0): one orbit, free flight from (g0, 0) back to g0 one period later."""
    orbs = rigid_stop_impacting(1, 0.1, 1, 1, 2.0, 1.0)
    assert len(orbs) == 1
    o = orbs[0]
    x_end = o.flow(o.t0 + o.T, o.t0, (o.g0, 0.0))[0]
    assert abs(x_end - o.g0) < 1e-12


def test_linear_discrete_converges_to_continuous():
    """Notes §6.1: every scheme converges to the continuous answer at its order; fourier is exact."""
    s = System.build(np.eye(2), [[2.0, -1.0], [-1.0, 1.5]], 0.8,
                     forces=[Force(0, 1.0, 1, 0.3), Force(1, 0.5, 2, -1.0), Force(1, 0.2, 0)], rayleigh=(0.1, 0.02))
    T = s.period
    for scheme, p in (("bds1", 1), ("bds2", 2), ("cds", 2), ("galerkin", 2)):
        errs = []
        for k in (256, 512):
            x, _, _ = linear_discrete(s, scheme, k)
            xe, _, _ = linear_response(s, np.arange(k) * T / k)
            errs.append(np.max(np.abs(x - xe)) / np.max(np.ptp(xe, axis=1)))
        rate = np.log2(errs[0] / errs[1])
        assert abs(rate - p) < 0.15, (scheme, errs, rate)
    x, v, a = linear_discrete(s, "fourier", 16)
    xe, ve, ae = linear_response(s, np.arange(16) * T / 16)
    np.testing.assert_allclose(x, xe, atol=1e-13)
    np.testing.assert_allclose(v, ve, atol=1e-13)
    np.testing.assert_allclose(a, ae, atol=1e-13)
