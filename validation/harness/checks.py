"""Comparisons of an engine output (CLI result or FMU samples) with the references, shared by
test_cli.py and test_fmu.py. Each returns the measured numbers and a list of failures (strings),
so that a test reports every deviation at once."""
from __future__ import annotations

import numpy as np

from marching.exact import linear_discrete, linear_response

from . import compare
from .cases import Case, Run

# Engine vs discrete marcher of the same equations: both solve the same k-periodic problem, one
# by an LCP over the period, the other by marching to a periodicity defect of 1e-11 (estimated
# distance to the periodic sequence < 1e-9). 1e-6 leaves room for the LCP residual and
# conditioning; anything larger means different equations (or another of several solutions).
TIGHT = 1e-6
# Engine vs the exact discrete formula of src/formulation.md §6.1 (linear case): round-off.
LINEAR_DISCRETE_TOL = 1e-9


def contract_failures(res, case: Case, run: Run) -> list[str]:
    """Shape/meaning checks of a CLI result against the contract."""
    s = case.system
    T = s.period
    k = run.steps
    fails = list(res.problems)
    if not np.isfinite(res.period) or abs(res.period - T) > 1e-12 * T:
        fails.append(f"period {res.period} != 2π/ω = {T}")
    if res.steps != k:
        fails.append(f"steps {res.steps} != {k}")
    if res.raw.get("scheme") != run.scheme:
        fails.append(f"scheme {res.raw.get('scheme')!r} != {run.scheme!r}")
    if res.raw.get("pairing") != run.pairing:
        fails.append(f"pairing {res.raw.get('pairing')!r} != {run.pairing!r}")
    if res.t.shape == (k,) and np.max(np.abs(res.t - np.arange(k) * T / k)) > 1e-12 * T:
        fails.append("time != j T/k")
    for d in case.output_dofs:
        if d not in res.x:
            fails.append(f"displacement of dof {d} missing")
        if d not in res.v:
            fails.append(f"velocity of dof {d} missing")
    if len(res.contact_dofs) != s.m:
        fails.append(f"{len(res.contact_dofs)} contacts in the result, scene has {s.m}")
    elif res.contact_dofs != [c.dof for c in s.contacts]:
        fails.append(f"contact dofs {res.contact_dofs} != {[c.dof for c in s.contacts]}")
    if fails:
        return fails
    if s.m:
        X = res.X(range(s.n))
        amp = max(float(np.max(np.ptp(X, axis=1))), 1e-300)
        tj = np.arange(k) * T / k
        clear = s.gaps(tj) - s.B @ X
        if np.max(np.abs(res.gap - clear)) > 1e-9 * amp:
            fails.append(f"contact gap != gap(t_j) - s x_j[dof] (max diff {np.max(np.abs(res.gap - clear)):.2e})")
        fmax = max(float(np.max(np.abs(res.force))), 1e-300)
        if np.min(res.force) < -1e-9 * fmax:
            fails.append(f"negative contact force {np.min(res.force):.3e}")
        pi = 1 if run.pairing == "forward" else 0
        gpair = np.roll(res.gap, -pi, axis=1)
        for i, c in enumerate(s.contacts):
            if c.rigid:
                if np.min(gpair[i]) < -1e-8 * amp:
                    fails.append(f"contact {i}: penetration {np.min(gpair[i]):.3e} at the paired instants")
                comp = np.max(np.abs(res.force[i] * gpair[i]))
                if comp > 1e-8 * amp * fmax:
                    fails.append(f"contact {i}: complementarity force*gap = {comp:.3e}")
            else:
                want = c.stiffness * np.maximum(0.0, -gpair[i])
                if np.max(np.abs(res.force[i] - want)) > 1e-8 * max(fmax, 1.0):
                    fails.append(f"contact {i}: compliant force != k_c max(0, -gap) at the paired instants "
                                 f"(max diff {np.max(np.abs(res.force[i] - want)):.2e})")
    lcp = res.lcp
    if isinstance(lcp.get("residual"), (int, float)) and not (lcp["residual"] <= 1e-8):
        fails.append(f"lcp.residual {lcp['residual']}")
    if isinstance(lcp.get("size"), int) and lcp["size"] != s.m * k:
        fails.append(f"lcp.size {lcp['size']} != m k = {s.m * k}")
    return fails


def vs_continuous(case: Case, run: Run, ref, t, X, V, force=None) -> dict:
    """Errors of samples (t, X (n_out, N), V) of the periodic response against the continuous
    reference; tolerances from compare.tolerance. Returns a dict of numbers and failures."""
    out: dict = {"fails": []}
    if case.kind == "linear":
        xe, ve, _ = linear_response(case.system, t)
    else:
        xe, ve = compare.ref_on_grid(ref, t)
    dofs = case.output_dofs
    xe, ve = xe[dofs], ve[dofs]
    out["x_max"], out["x_rms"] = compare.errors(xe, X)
    out["v_max"], out["v_rms"] = compare.errors(ve, V)
    out["tol_x"] = compare.tolerance(case, run.scheme, run.pairing, run.steps, "x")
    out["tol_v"] = compare.tolerance(case, run.scheme, run.pairing, run.steps, "v")
    if out["tol_x"] is None:
        out["fails"].append(f"no convergence expected for {case.kind} {run.scheme}/{run.pairing}: not a valid run")
    elif out["x_max"] > out["tol_x"]:
        out["fails"].append(f"displacement error {out['x_max']:.3e} > tol {out['tol_x']:.3e}")
    if out["tol_v"] is not None and out["v_max"] > out["tol_v"]:
        out["fails"].append(f"velocity error {out['v_max']:.3e} > tol {out['tol_v']:.3e}")
    return out


def impulse_and_onset(case: Case, run: Run, ref, t, force, impulse, period) -> dict:
    """Impulse per period (asserted with the impulse tolerance) and phase of the first impact of
    each contact (asserted within 2/k + tol_x of the reference phase)."""
    out: dict = {"fails": [], "onsets": [], "ref_onsets": []}
    if not case.system.m:
        return out
    out["impulse_err"] = compare.impulse_error(ref.impulse, impulse)
    out["tol_impulse"] = compare.tolerance(case, run.scheme, run.pairing, run.steps, "impulse")
    if out["tol_impulse"] is not None and out["impulse_err"] > out["tol_impulse"]:
        out["fails"].append(f"impulse per period {impulse} vs {ref.impulse}: rel. error {out['impulse_err']:.3e} "
                            f"> tol {out['tol_impulse']:.3e}")
    tol_x = compare.tolerance(case, run.scheme, run.pairing, run.steps, "x") or 0.0
    for i in range(case.system.m):
        ph = compare.onset_phase(t, force[i:i + 1], period)
        ref_ph = ref.first_onset_phase(i)
        out["onsets"].append(ph)
        out["ref_onsets"].append(ref_ph)
        if ph is None or ref_ph is None:
            if (ph is None) != (ref_ph is None):
                out["fails"].append(f"contact {i}: impact in one solution only (engine {ph}, reference {ref_ph})")
            continue
        if compare.phase_distance(ph, ref_ph) > 2.0 / run.steps + tol_x:
            out["fails"].append(f"contact {i}: first impact at phase {ph:.5f}, reference {ref_ph:.5f}")
    return out


def vs_discrete(case: Case, run: Run, disc, X, V, force) -> dict:
    """Engine samples at t_j = j T/k against the discrete marcher (same equations): TIGHT."""
    out: dict = {"fails": []}
    dofs = case.output_dofs
    out["x_max"], out["x_rms"] = compare.errors(disc.x[dofs], X)
    out["v_max"], _ = compare.errors(disc.v[dofs], V)
    if out["x_max"] > TIGHT:
        out["fails"].append(f"displacement differs from the discrete marcher by {out['x_max']:.3e} > {TIGHT:g}")
    if out["v_max"] > TIGHT:
        out["fails"].append(f"velocity differs from the discrete marcher by {out['v_max']:.3e} > {TIGHT:g}")
    if case.system.m:
        fmax = max(float(np.max(np.abs(disc.force))), 1e-300)
        out["f_max"] = float(np.max(np.abs(force - disc.force))) / fmax
        if out["f_max"] > TIGHT:
            out["fails"].append(f"contact force differs from the discrete marcher by {out['f_max']:.3e} "
                                f"(relative to its max) > {TIGHT:g}")
    return out


def vs_linear_discrete(case: Case, run: Run, X, V) -> dict:
    x, v, _ = linear_discrete(case.system, run.scheme, run.steps)
    dofs = case.output_dofs
    out: dict = {"fails": []}
    out["x_max"], out["x_rms"] = compare.errors(x[dofs], X)
    out["v_max"], _ = compare.errors(v[dofs], V)
    if out["x_max"] > LINEAR_DISCRETE_TOL or out["v_max"] > LINEAR_DISCRETE_TOL:
        out["fails"].append(f"linear {run.scheme}: differs from the exact discrete formula by x {out['x_max']:.3e}, "
                            f"v {out['v_max']:.3e} > {LINEAR_DISCRETE_TOL:g}")
    return out
