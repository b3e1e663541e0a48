"""The independent time marchers against the exact references, against each other, and against
the discrete equations they claim to solve. No engine binaries needed.

Measured numbers are recorded in errors.md (harness.report.FIGURES) (section "marchers")."""
import numpy as np
import pytest

from harness.cases import CASES, continuous
from harness.report import REPORT, Row
from marching.central_difference import march_cds
from marching.compliant import march_compliant
from marching.exact import (compliant_stop, linear_discrete, linear_response, rigid_stop_impacting,
                            rigid_stop_sticking)
from marching.model import Contact, Force, Motion, System, relative_errors
from marching.multistep import march_multistep, stencils
from marching.rigid import march_rigid

# ------------------------------------------------------------------ exact references of src/formulation.md §6

COMPLIANT = (1, 0.05, 1, 10, 1, 1, 1.3)   # m, c, k, kc, g0, F, Ω
STICKING = (1, 0.1, 1, 1, 0.5, 1)          # m, c, k, F, g0, Ω
IMPACTING = (1, 0.1, 1, 1, 2.0, 1.0)


def _sys_compliant():
    return CASES["compliant_1dof"].system


def _sys_sticking():
    return CASES["rigid_stick_1dof"].system


def _sys_impacting():
    return System.build([[1.0]], [[1.0]], 1.0, forces=[Force(0, 1.0)], contacts=[Contact(0, 2.0)], damping=[[0.1]])


def _cost(r):
    return f"{r.periods} periods, {r.cpu_time:.2f} s CPU"


def _row(case, what, ex, er, tol, imp="", onset="", cost="", ok=True):
    REPORT.add(Row(case, what, ex, er, tol, imp, onset, cost, "pass" if ok else "FAIL"))


def test_compliant_marcher_vs_exact():
    """compliant.py (events at the switches) reproduces the bilinear orbit: x and v to < 1e-7 of
    the peak-to-peak amplitude (measured ~3e-9), impulse to 1e-8 relative, contact entry phase to
    1e-8."""
    r = continuous("compliant_1dof")
    o = compliant_stop(*COMPLIANT)
    y = o.state(r.t)
    ex, er = relative_errors(y[0:1], r.x)
    ev, _ = relative_errors(y[1:2], r.v)
    di = abs(r.impulse[0] - o.impulse()) / o.impulse()
    dph = abs(r.first_onset_phase() - o.t0 / o.T)
    ok = ex < 1e-7 and ev < 1e-7 and di < 1e-8 and dph < 1e-8
    _row("compliant_1dof", "compliant.py vs exact (src/formulation.md §6.2)", ex, er, 1e-7,
         f"{r.impulse[0]:.8f} (exact {o.impulse():.8f})", f"{r.first_onset_phase():.9f} (exact {o.t0 / o.T:.9f})",
         _cost(r), ok)
    assert ex < 1e-7 and ev < 1e-7, (ex, ev)
    assert di < 1e-8, di
    assert dph < 1e-8, dph
    assert r.defect < 1e-9


def test_rigid_marcher_vs_exact_sticking():
    """rigid.py reproduces the sticking orbit of src/formulation.md §6.3: x, v to 1e-8 (measured ~1e-10),
    impulse 2.80804 to 1e-8 relative, the impact instant and the sticking force."""
    r = continuous("rigid_stick_1dof")
    o = rigid_stop_sticking(*STICKING)
    y = o.state(r.t)
    ex, er = relative_errors(y[0:1], r.x)
    ev, _ = relative_errors(y[1:2], r.v)
    di = abs(r.impulse[0] - o.impulse) / o.impulse
    (t_imp, i_imp, P), = r.impacts
    ok = ex < 1e-8 and ev < 1e-8 and di < 1e-8
    _row("rigid_stick_1dof", "rigid.py vs exact (src/formulation.md §6.3)", ex, er, 1e-8,
         f"{r.impulse[0]:.8f} (exact {o.impulse:.8f})", f"{t_imp / o.T:.9f} (exact {(o.th % o.T) / o.T:.9f})",
         _cost(r), ok)
    assert ex < 1e-8 and ev < 1e-8, (ex, ev)
    assert di < 1e-8
    assert abs(t_imp - o.th % o.T) < 1e-8
    assert abs(P - o.impact_impulse) < 1e-8
    assert np.max(np.abs(r.force[0] - o.force(r.t))) < 1e-8
    assert abs(min(r.x[0].min(), o.min_x()) - (-1.869854)) < 1e-6  # the sampled minimum is above it
    assert r.x[0].min() >= o.min_x() - 1e-10


def test_rigid_marcher_vs_exact_impacting():
    """Pure impacts (no sticking): x, v to 1e-8 (measured ~7e-11), impulse and impact phase."""
    r = march_rigid(_sys_impacting(), tol=1e-9, samples=2048)
    o, = rigid_stop_impacting(*IMPACTING)
    y = o.state(r.t)
    ex, er = relative_errors(y[0:1], r.x)
    ev, _ = relative_errors(y[1:2], r.v)
    (t_imp, _, P), = r.impacts
    _row("impacting_1dof", "rigid.py vs exact (no sticking)", ex, er, 1e-8,
         f"{r.impulse[0]:.8f} (exact {o.impulse:.8f})", f"{t_imp / o.T:.9f} (exact {o.t0 / o.T:.9f})", _cost(r),
         ex < 1e-8)
    assert ex < 1e-8 and ev < 1e-8, (ex, ev)
    assert abs(P - o.impulse) / o.impulse < 1e-8
    assert abs(t_imp - o.t0) < 1e-8
    assert not r.force.any()  # never sticks


# ------------------------------------------------------------------ central differences, orders


def _orders(errs, ks):
    return [np.log(errs[i] / errs[i + 1]) / np.log(ks[i + 1] / ks[i]) for i in range(len(ks) - 1)]


def test_cds_rigid_sticking_second_order():
    """cds + forward-increment multipliers converge at O(h²) to the plastic orbit with sticking:
    err <= 0.35 (ωh)² (measured constant 0.111), impulse within 0.3 (ωh)² (measured 0.092)."""
    s = _sys_sticking()
    o = rigid_stop_sticking(*STICKING)
    ks = (128, 256, 512, 1024)
    errs = []
    for k in ks:
        r = march_cds(s, k)
        ex, er = relative_errors(o.state(r.t)[0:1], r.x)
        di = abs(r.impulse[0] - o.impulse) / o.impulse
        tol = 0.35 * (s.omega * s.period / k) ** 2
        _row("rigid_stick_1dof", f"central_difference.py k={k} vs exact", ex, er, tol, f"{r.impulse[0]:.6f}",
             f"{r.first_onset_phase():.5f}", _cost(r), ex <= tol)
        assert ex <= tol, (k, ex, tol)
        assert di <= 0.3 * (s.omega * s.period / k) ** 2, (k, di)
        assert abs(r.first_onset_phase() - (o.th % o.T) / o.T) <= 2.0 / k
        errs.append(ex)
    assert all(1.8 < p < 2.2 for p in _orders(errs, ks)), _orders(errs, ks)


def test_cds_rigid_impacting_first_order():
    """Without sticking every fixed-grid scheme is first order (the impact falls between samples):
    err <= 0.75 (ωh) (measured constant 0.17-0.24, oscillating with the impact's position)."""
    s = _sys_impacting()
    o, = rigid_stop_impacting(*IMPACTING)
    for k in (128, 256, 512, 1024):
        r = march_cds(s, k)
        ex, er = relative_errors(o.state(r.t)[0:1], r.x)
        tol = 0.75 * (s.omega * s.period / k)
        _row("impacting_1dof", f"central_difference.py k={k} vs exact", ex, er, tol, f"{r.impulse[0]:.6f}",
             f"{r.first_onset_phase():.5f}", _cost(r), ex <= tol)
        assert ex <= tol, (k, ex, tol)
        assert abs(r.impulse[0] - o.impulse) / o.impulse <= tol
        # forward pairing: the force sample j enforces the clearance at j+1, so impact in (t_j, t_j+1]
        assert -1e-12 <= o.t0 / o.T - r.first_onset_phase() <= 1.0 / k + tol


@pytest.mark.parametrize("pairing,p,C", [("same", 2, 0.2), ("forward", 1, 4.0)])
def test_cds_compliant_orders(pairing, p, C):
    """Compliant contact: same-instant pairing second order (measured C = 0.045 on ω_max h,
    ω_max = sqrt(11)), forward pairing first order (force lags a step; measured C = 1.34)."""
    s = _sys_compliant()
    o = compliant_stop(*COMPLIANT)
    wmax = s.max_frequency()
    ks = (128, 256, 512)
    errs = []
    for k in ks:
        r = march_cds(s, k, pairing=pairing)
        ex, er = relative_errors(o.state(r.t)[0:1], r.x)
        tol = C * (wmax * s.period / k) ** p
        _row("compliant_1dof", f"central_difference.py {pairing} k={k} vs exact", ex, er, tol, f"{r.impulse[0]:.6f}",
             f"{r.first_onset_phase():.5f}", _cost(r), ex <= tol)
        assert ex <= tol, (k, ex, tol)
        errs.append(ex)
    assert all(p - 0.25 < q < p + 0.25 for q in _orders(errs, ks)), _orders(errs, ks)


# ------------------------------------------------------------------ discrete marchers


@pytest.mark.parametrize("name,pairing", [("rigid_stick_1dof", "forward"), ("compliant_1dof", "same"),
                                          ("rigid_3dof_two_contacts", "forward"), ("compliant_2dof", "forward")])
def test_multistep_cds_equals_central_difference(name, pairing):
    """The generic implicit marcher with the cds stencil and the explicit predictor/corrector of
    src/formulation.md §5 are the same recursion: equal to round-off."""
    s = CASES[name].system
    a = march_cds(s, 256, pairing=pairing, tol=1e-12)
    b = march_multistep(s, "cds", 256, pairing=pairing, tol=1e-12)
    scale = np.max(np.ptp(a.x, axis=1))
    assert np.max(np.abs(a.x - b.x)) < 1e-9 * scale
    assert np.max(np.abs(a.impulse - b.impulse)) < 1e-9 * max(1.0, np.max(a.impulse))


@pytest.mark.parametrize("name,scheme,pairing", [
    ("rigid_stick_1dof", "cds", "forward"), ("rigid_stick_1dof", "galerkin", "forward"),
    ("rigid_stick_1dof", "bds1", "same"), ("compliant_1dof", "bds2", "same"), ("compliant_1dof", "galerkin", "same"),
    ("compliant_1dof", "cds", "same"), ("rigid_3dof_two_contacts", "cds", "forward"),
    ("moving_obstacle", "bds2", "same")])
def test_discrete_marcher_solves_periodic_equations(name, scheme, pairing):
    """The last period of a discrete marcher satisfies the periodic equations of src/formulation.md §2-3:
    Σ_l (α_l M + β_l C + γ_l K) x_{j+l} + B^T z_j = Σ_l γ_l f_{j+l} (cyclic), z >= 0, and
    complementarity with the clearance at j + π (π = 1 forward, 0 same; a compliant contact
    z = k_c max(0, penetration))."""
    s = CASES[name].system
    k = 256
    r = march_cds(s, k, pairing=pairing, tol=1e-12) if scheme == "cds" else \
        march_multistep(s, scheme, k, pairing=pairing, tol=1e-12)
    h = s.period / k
    al, be, ga = stencils(scheme, h)
    X, Z = r.x, r.force
    tj = np.arange(k) * h
    F = s.force(tj)
    lhs = s.B.T @ Z
    rhs = np.zeros_like(F)
    for l in set(al) | set(be) | set(ga):
        Xl = np.roll(X, -l, axis=1)
        lhs = lhs + (al.get(l, 0) * s.mass + be.get(l, 0) * s.damping + ga.get(l, 0) * s.stiffness) @ Xl
        rhs = rhs + ga.get(l, 0) * np.roll(F, -l, axis=1)
    scale = np.max(np.abs(rhs)) + np.max(np.abs(s.B.T @ Z))
    assert np.max(np.abs(lhs - rhs)) < 1e-8 * scale
    pi = 1 if pairing == "forward" else 0
    clear = s.gaps(np.roll(tj, -pi)) - s.B @ np.roll(X, -pi, axis=1)
    amp = np.max(np.ptp(X, axis=1))
    assert np.all(Z >= 0)
    for i, c in enumerate(s.contacts):
        if c.rigid:
            assert np.all(clear[i] >= -1e-9 * amp)
            assert np.max(np.abs(Z[i] * clear[i])) < 1e-8 * amp * max(1.0, np.max(Z[i]))
        else:
            np.testing.assert_allclose(Z[i], c.stiffness * np.maximum(0.0, -clear[i]), atol=1e-8 * max(1.0, Z[i].max()))


def test_discrete_marchers_linear_equal_symbols():
    """Without contact the discrete marchers converge to the symbol formula of src/formulation.md §6.1 (x, v, a)."""
    s = CASES["linear_2dof"].system
    for scheme in ("bds1", "bds2", "cds", "galerkin"):
        r = march_cds(s, 128, pairing="same", tol=1e-12) if scheme == "cds" else \
            march_multistep(s, scheme, 128, tol=1e-12)
        x, v, a = linear_discrete(s, scheme, 128)
        sc = np.max(np.ptp(x, axis=1))
        assert np.max(np.abs(r.x - x)) < 1e-9 * sc, scheme
        assert np.max(np.abs(r.v - v)) < 1e-8 * np.max(np.ptp(v, axis=1)), scheme
        assert np.max(np.abs(r.a - a)) < 1e-7 * np.max(np.ptp(a, axis=1)), scheme


def test_continuous_marcher_linear():
    """compliant.py without contact = the exact linear response (3 harmonics, 2 DOFs), 1e-8."""
    r = continuous("linear_2dof")
    s = r.system
    x, v, _ = linear_response(s, r.t)
    ex, er = relative_errors(x, r.x)
    ev, _ = relative_errors(v, r.v)
    _row("linear_2dof", "compliant.py (no contact) vs exact", ex, er, 1e-8, "", "", _cost(r), ex < 1e-8)
    assert ex < 1e-8 and ev < 1e-8, (ex, ev)


# ------------------------------------------------------------------ moving obstacles, multi-DOF


def test_rigid_persistent_contact_moving_obstacle():
    """Notes §6.4: an obstacle that keeps the contact closed (static push 2 > k gap): rigid.py has
    x = gap(t) and force = f - m gap'' - c gap' - k gap to 1e-9; cds (forward) has x_j = gap_j
    exactly and the force at O(h²) (err <= 0.35 (ωh)² relative)."""
    s = System.build([[1.0]], [[1.0]], 1.0, forces=[Force(0, 1.0, 1), Force(0, 2.0, 0)],
                     contacts=[Contact(0, 0.5, motion=(Motion(0.1, 2, 0.3),))], damping=[[0.1]])

    def z_exact(t):
        return s.force(t)[0] - s.gaps(t, 2)[0] - 0.1 * s.gaps(t, 1)[0] - s.gaps(t)[0]

    r = march_rigid(s, samples=1024)
    assert z_exact(r.t).min() > 0.7
    assert np.max(np.abs(r.x[0] - s.gaps(r.t)[0])) < 1e-9
    assert np.max(np.abs(r.force[0] - z_exact(r.t))) < 1e-9
    for k in (128, 256):
        c = march_cds(s, k)
        assert np.max(np.abs(c.x[0] - s.gaps(c.t)[0])) < 1e-12
        zerr = np.max(np.abs(c.force[0] - z_exact(c.t))) / np.ptp(z_exact(c.t))
        assert zerr <= 0.35 * (s.omega * s.period / k) ** 2, (k, zerr)


def test_rigid_moving_obstacle_intermittent_cds_converges():
    """Intermittent contact with a moving rigid obstacle: cds converges to rigid.py at O(h²)
    (sticking orbit; measured constant 0.09 on ωh)."""
    s = System.build([[1.0]], [[1.0]], 1.0, forces=[Force(0, 1.0)],
                     contacts=[Contact(0, 0.5, motion=(Motion(0.1, 2, 0.3),))], damping=[[0.1]])
    r = march_rigid(s, samples=4096)
    assert r.impacts and r.force.any()  # impacts and sticking phases
    errs = []
    for k in (256, 512, 1024):
        c = march_cds(s, k)
        ex, _ = relative_errors(r.x[:, ::4096 // k], c.x)
        assert ex <= 0.35 * (s.omega * s.period / k) ** 2, (k, ex)
        assert abs(c.impulse[0] - r.impulse[0]) / r.impulse[0] <= 0.3 * (s.omega * s.period / k) ** 2
        errs.append(ex)
    assert all(1.7 < p < 2.3 for p in _orders(errs, (256, 512, 1024))), errs


def test_rigid_multi_dof_two_contacts_cds_converges():
    """3-DOF chain with two rigid stops: cds (forward) converges to rigid.py, err <= 0.35 (ω_max h)²
    (measured constant 0.05, order ~2); impulses per contact likewise."""
    case = CASES["rigid_3dof_two_contacts"]
    s = case.system
    r = continuous(case.name)
    assert len(r.impacts) == 2 and set(i for _, i, _ in r.impacts) == {0, 1}
    wmax = s.max_frequency()
    errs = []
    for k in (256, 512):
        c = march_cds(s, k)
        ex, er = relative_errors(r.x[:, ::r.t.size // k], c.x)
        tol = 0.35 * (wmax * s.period / k) ** 2
        _row(case.name, f"central_difference.py k={k} vs rigid.py", ex, er, tol,
             ", ".join(f"{v:.5f}" for v in c.impulse) + " (rigid.py " + ", ".join(f"{v:.5f}" for v in r.impulse) + ")",
             f"{c.first_onset_phase():.5f} (rigid.py {r.first_onset_phase():.5f})", _cost(c), ex <= tol)
        assert ex <= tol, (k, ex, tol)
        assert np.max(np.abs(c.impulse - r.impulse) / r.impulse) <= 0.3 * (wmax * s.period / k) ** 2
        errs.append(ex)
    assert 1.7 < np.log2(errs[0] / errs[1]) < 2.3


def test_compliant_marcher_multi_dof_and_moving_obstacle_vs_cds():
    """compliant.py on the 2-DOF chain and on the moving obstacle agrees with cds (same pairing) at
    k = 1024 within 0.2 (ω_max h)² (measured constants 0.033 and 0.057)."""
    for name in ("compliant_2dof", "moving_obstacle"):
        s = CASES[name].system
        r = continuous(name)
        k = 1024
        c = march_cds(s, k, pairing="same")
        ex, er = relative_errors(r.x[:, ::r.t.size // k], c.x)
        tol = 0.2 * (s.max_frequency() * s.period / k) ** 2
        _row(name, f"central_difference.py same k={k} vs compliant.py", ex, er, tol,
             f"{c.impulse[0]:.6f} (compliant.py {r.impulse[0]:.6f})", "", _cost(c), ex <= tol)
        assert ex <= tol, (name, ex, tol)


def test_continuous_marchers_cost():
    """Record periods and CPU time of the continuous marchers on every case (and check that they
    converged: periodicity defect below the tolerance, estimated distance to the orbit < 1e-7)."""
    for name in CASES:
        r = continuous(name)
        REPORT.add(Row(name, f"marcher {r.method} (tol {r.info['tol']:.0e})", None, None, None,
                       ", ".join(f"{v:.6f}" for v in r.impulse),
                       "" if r.first_onset_phase() is None else f"{r.first_onset_phase():.6f}",
                       f"{r.periods} periods, {r.cpu_time:.2f} s CPU, defect {r.defect:.1e}, "
                       f"bound {r.error_bound:.1e}", "pass"))
        assert r.defect < r.info["tol"]
        assert r.error_bound < 1e-7, (name, r.error_bound)


def test_rigid_coupled_mass_matrix_cds_converges():
    """Non-diagonal (consistent) mass matrix: the impact impulse acts through M^-1 on both DOFs.
    rigid.py and cds (forward) agree at O(h²), err <= 0.35 (ω_max h)² (measured constant 0.1;
    the orbit has two impacts and a sticking phase per period)."""
    M = np.array([[2.0, 0.5], [0.5, 1.0]])
    s = System.build(M, [[2.0, -1.0], [-1.0, 1.0]], 0.5, forces=[Force(1, 0.4)], contacts=[Contact(1, 0.8)],
                     rayleigh=(0.05, 0.05))
    r = march_rigid(s, samples=4096)
    assert len(r.impacts) == 2 and r.force.any()
    wmax = s.max_frequency()
    errs = []
    for k in (256, 512):
        c = march_cds(s, k)
        ex, _ = relative_errors(r.x[:, ::4096 // k], c.x)
        assert ex <= 0.35 * (wmax * s.period / k) ** 2, (k, ex)
        errs.append(ex)
    assert 1.7 < np.log2(errs[0] / errs[1]) < 2.3


def test_contact_lcp_many_contacts():
    """The step LCP grows the active set beyond the predicted one when the correction of one
    contact pushes a coupled neighbour into its obstacle, and handles m > 8 contacts."""
    from marching.model import solve_contact_lcp, solve_lcp_enum, solve_lcp_murty

    rng = np.random.default_rng(1)
    for m in (3, 5, 12, 20):
        A = rng.normal(size=(m, m))
        G = A @ A.T + m * np.eye(m)  # SPD
        for _ in range(20):
            cp = rng.normal(size=m)
            z = solve_contact_lcp(G, cp)
            w = G @ z + cp
            assert np.all(z >= 0) and np.all(w >= -1e-10) and abs(z @ w) < 1e-9
            np.testing.assert_allclose(z, solve_lcp_murty(G, cp), atol=1e-10)  # unique (P-matrix)
            if m <= 8:
                np.testing.assert_allclose(z, solve_lcp_enum(G, cp), atol=1e-10)
