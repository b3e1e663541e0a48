"""Shooting, Floquet multipliers and pseudo-arclength continuation in Ω for NLvib's Example 03.

A periodic orbit of period p·T (T = 2π/Ω) is a root of R(s, Ω) = Φ_{pT}(s) - s, s = y(0), with
Φ the exact flow of flow.py. Its Floquet multipliers are the eigenvalues of the exact monodromy
∂Φ_{pT}/∂s (identity saltation: the field is continuous, see flow.py).

Continuation: unknowns u = (s, W·Ω) (W = OMEGA_WEIGHT puts the 0.3-wide Ω range on the scale of the
state, a few units); Keller's pseudo-arclength corrector: R(u) = 0 and t_k·(u - u_k) = σ, Newton with
the exact Jacobian [∂R/∂s, ∂R/∂Ω / W]. Events between two accepted points are located by solving
along that same parametrisation u(σ), σ in (0, ds), with test functions (Kuznetsov, "Elements of
Applied Bifurcation Theory", §10.2 and §10.3; Seydel, "Practical Bifurcation and Stability
Analysis", §5):
  fold             the Ω-component of the tangent                 (Brent)
  period_doubling  det(M + I) = Π (μ_i + 1)                       (Brent)
  neimark_sacker   Π_{i<j} (μ_i μ_j - 1) (bialternate product);    (Brent, then kept only if the
                   pair with μ_i μ_j = 1 is complex on |μ| = 1 — else a neutral saddle, not an event)
  branch_point     det([∂R/∂u; t^T]) with t oriented continuously  (Brent)
  grazing          the number of x0 = gap crossings per period     (bisection: it is an integer)
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy.optimize import brentq

from .flow import GAP, Nlvib03

OMEGA_WEIGHT = 10.0
NEWTON_TOL = 1e-11          # ‖R‖∞ at convergence; R is exact to ~1e-13 (states of a few units)
SIGMA_TOL = 1e-13           # event location: arclength tolerance (scaled units; ΔΩ <= 1e-14)


@dataclass
class Orbit:
    omega: float
    s: np.ndarray
    period_multiple: int
    multipliers: np.ndarray
    monodromy: np.ndarray
    domega: np.ndarray
    measures: dict = field(default_factory=dict)
    tangent: np.ndarray | None = None

    @property
    def max_multiplier(self) -> float:
        return float(np.max(np.abs(self.multipliers)))

    @property
    def stable(self) -> bool:
        return self.max_multiplier < 1.0

    def u(self) -> np.ndarray:
        return np.append(self.s, OMEGA_WEIGHT * self.omega)


class ShootingFailed(RuntimeError):
    pass


def residual(s, omega: float, p: int = 1, sensitivities: bool = True):
    """R = Φ_{pT}(s) - s with its monodromy and dΦ_{pT}/dΩ."""
    sysm = Nlvib03(omega)
    res = sysm.integrate(0.0, s, p * sysm.T, sensitivities)
    if sensitivities:
        fT = sysm.regimes[int(res.segments[-1].contact)].field(p * sysm.T, res.y)
        res.domega = res.domega + fT * (-2 * np.pi * p / omega ** 2)
    return res.y - np.asarray(s, dtype=float), res


def make_orbit(s, omega: float, p: int = 1, measures: bool = True) -> Orbit:
    R, res = residual(s, omega, p)
    mu = np.linalg.eigvals(res.monodromy)
    mu = mu[np.argsort(-np.abs(mu))]
    o = Orbit(float(omega), np.asarray(s, dtype=float).copy(), p, mu, res.monodromy, res.domega)
    if measures:
        o.measures = orbit_measures(o.s, omega, p)
    return o


def orbit_measures(s, omega: float, p: int = 1) -> dict:
    return Nlvib03(omega).orbit_measures(s, p)


def shoot(s0, omega: float, p: int = 1, tol: float = NEWTON_TOL, max_iter: int = 30) -> Orbit:
    """Newton on Φ_{pT}(s) - s = 0 at fixed Ω with the exact monodromy."""
    s = np.asarray(s0, dtype=float).copy()
    for _ in range(max_iter):
        R, res = residual(s, omega, p)
        if np.max(np.abs(R)) < tol:
            return make_orbit(s, omega, p)
        ds = np.linalg.solve(res.monodromy - np.eye(4), -R)
        lim = 1.0                      # damped step: at most one unit of state per iteration
        s = s + ds * min(1.0, lim / max(np.max(np.abs(ds)), 1e-300))
    raise ShootingFailed(f"shooting at Ω = {omega} did not converge (‖R‖ = {np.max(np.abs(R)):.2e})")


# ---------------------------------------------------------------------- continuation
def _jac(res, p: int) -> np.ndarray:
    return np.column_stack([res.monodromy - np.eye(4), res.domega / OMEGA_WEIGHT])


def _tangent(J: np.ndarray, t_ref: np.ndarray) -> np.ndarray:
    t = np.linalg.solve(np.vstack([J, t_ref]), np.eye(5)[4])
    return t / np.linalg.norm(t)


def correct(u_pred: np.ndarray, t_k: np.ndarray, u_k: np.ndarray, sigma: float, p: int = 1,
            max_iter: int = 12):
    """Newton on R(u) = 0, t_k·(u - u_k) = σ from u_pred. Returns (u, res, iterations) or None."""
    u = u_pred.copy()
    for it in range(max_iter):
        R, res = residual(u[:4], u[4] / OMEGA_WEIGHT, p)
        c = t_k @ (u - u_k) - sigma
        if np.max(np.abs(R)) < NEWTON_TOL and abs(c) < 1e-13:
            return u, res, it
        J = _jac(res, p)
        du = np.linalg.solve(np.vstack([J, t_k]), -np.append(R, c))
        if not np.all(np.isfinite(du)) or np.linalg.norm(du) > 1.0:
            return None
        u = u + du
    return None


def _orbit_at(u, res, t_ref, p) -> Orbit:
    mu = np.linalg.eigvals(res.monodromy)
    mu = mu[np.argsort(-np.abs(mu))]
    o = Orbit(u[4] / OMEGA_WEIGHT, u[:4].copy(), p, mu, res.monodromy, res.domega)
    J = _jac(res, p)
    o.tangent = _tangent(J, t_ref)
    o.measures = orbit_measures(o.s, o.omega, p)
    return o


def _bialternate(mu: np.ndarray) -> float:
    v = 1.0 + 0j
    for i in range(len(mu)):
        for j in range(i + 1, len(mu)):
            v *= mu[i] * mu[j] - 1.0
    return float(v.real)


def monitor_functions(o: Orbit) -> dict:
    J = _jac_from_orbit(o)
    return {
        "fold": float(o.tangent[4]),
        "period_doubling": float(np.real(np.prod(o.multipliers + 1.0))),
        "neimark_sacker": _bialternate(o.multipliers),
        "branch_point": float(np.linalg.det(np.vstack([J, o.tangent]))),
        "grazing": o.measures["switches"],
    }


def _jac_from_orbit(o: Orbit) -> np.ndarray:
    return np.column_stack([o.monodromy - np.eye(4), o.domega / OMEGA_WEIGHT])


@dataclass
class Event:
    kind: str
    orbit: Orbit
    detail: str = ""


@dataclass
class Branch:
    orbits: list[Orbit]
    events: list[Event]
    period_multiple: int = 1
    label: str = ""


def _point_on_step(o_k: Orbit, sigma: float, p: int):
    u_k = o_k.u()
    got = correct(u_k + sigma * o_k.tangent, o_k.tangent, u_k, sigma, p)
    if got is None:
        raise ShootingFailed(f"corrector failed inside a step at σ = {sigma}")
    u, res, _ = got
    return _orbit_at(u, res, o_k.tangent, p)


def _locate(o_k: Orbit, o_n: Orbit, sigma_n: float, kind: str, p: int) -> Orbit:
    """The orbit where test function `kind` changes sign between o_k (σ = 0) and o_n (σ = sigma_n)."""
    cache = {}

    def point(sig):
        if sig not in cache:
            cache[sig] = o_k if sig == 0 else (o_n if sig == sigma_n else _point_on_step(o_k, sig, p))
        return cache[sig]

    if kind == "grazing":
        a, b = 0.0, sigma_n
        na = o_k.measures["switches"]
        while b - a > SIGMA_TOL:
            m = 0.5 * (a + b)
            if point(m).measures["switches"] == na:
                a = m
            else:
                b = m
        # report the contact-side end: its max x0 - gap is the (positive, tiny) penetration
        oa, ob = point(a), point(b)
        return oa if oa.measures["switches"] > ob.measures["switches"] else ob
    sig = brentq(lambda x: monitor_functions(point(x))[kind], 0.0, sigma_n, xtol=SIGMA_TOL, rtol=4 * np.finfo(float).eps)
    return point(sig)


def _classify_ns(o: Orbit) -> tuple[bool, str]:
    mu = o.multipliers
    best, pair = np.inf, None
    for i in range(4):
        for j in range(i + 1, 4):
            d = abs(mu[i] * mu[j] - 1.0)
            if d < best:
                best, pair = d, (mu[i], mu[j])
    complex_pair = abs(pair[0].imag) > 1e-8 and abs(pair[0] - np.conj(pair[1])) < 1e-6
    desc = f"pair {pair[0]:.6f}, {pair[1]:.6f}"
    return complex_pair, desc


def continuation(o0: Orbit, direction: float, omega_range=(0.5, 0.8), ds0: float = 0.02,
                 ds_max: float = 0.08, ds_min: float = 1e-7, max_points: int = 3000,
                 max_angle: float = 0.1, p: int = 1, log=None, stop=None,
                 start_tangent: np.ndarray | None = None) -> Branch:
    """Pseudo-arclength continuation from orbit o0 in the direction of increasing (direction=+1)
    or decreasing Ω, until Ω leaves omega_range (the last point is corrected onto the bound), the
    or `stop(cur, nxt)` returns an end orbit (appended last; the step to nxt is dropped). ds in scaled units of u = (s, W·Ω)."""
    R, res = residual(o0.s, o0.omega, p)
    J = _jac(res, p)
    t_ref = np.zeros(5)
    t_ref[4] = direction
    if start_tangent is not None:
        # branch switching: the branch point's Jacobian has a 2-D kernel, the caller picks the way
        t0 = start_tangent / np.linalg.norm(start_tangent)
    elif o0.tangent is None or abs(o0.tangent[4]) < 1e-3:
        # start: the tangent with the requested Ω direction
        t0 = _tangent(J, t_ref)
        if t0[4] * direction < 0:
            t0 = -t0
    else:
        t0 = o0.tangent if o0.tangent[4] * direction > 0 else -o0.tangent
    cur = _orbit_at(o0.u(), res, t0, p)
    cur.tangent = t0
    if log:
        log(f"continuation ({p}T) from Ω = {cur.omega:.6f}, A0 = {cur.measures['amplitude_0']:.6f}")
    orbits, events = [cur], []
    ds = ds0
    lo, hi = omega_range
    while len(orbits) < max_points:
        u_k, t_k = cur.u(), cur.tangent
        got = correct(u_k + ds * t_k, t_k, u_k, ds, p)
        if got is None:
            ds *= 0.5
            if ds < ds_min:
                raise ShootingFailed(f"continuation stalled at Ω = {cur.omega:.6f}")
            continue
        u, res, it = got
        nxt = _orbit_at(u, res, t_k, p)
        ang = np.arccos(np.clip(nxt.tangent @ t_k, -1, 1))
        if ang > max_angle and ds > ds_min * 2:
            ds *= 0.5
            continue
        if stop is not None:
            end = stop(cur, nxt)
            if end is not None:
                orbits.append(end)
                break
        # events on (cur, nxt]
        fa, fb = monitor_functions(cur), monitor_functions(nxt)
        for kind in ("fold", "period_doubling", "neimark_sacker", "branch_point"):
            if fa[kind] * fb[kind] < 0:
                ev = _locate(cur, nxt, ds, kind, p)
                detail = ""
                if kind == "neimark_sacker":
                    ok, detail = _classify_ns(ev)
                    if not ok:
                        if log:
                            log(f"  neutral saddle (not an event) at Ω = {ev.omega:.10f}: {detail}")
                        continue
                events.append(Event(kind, ev, detail))
                if log:
                    log(f"  {kind} at Ω = {ev.omega:.10f}, A0 = {ev.measures['amplitude_0']:.6f} {detail}")
        if fa["grazing"] != fb["grazing"]:
            ev = _locate(cur, nxt, ds, "grazing", p)
            detail = f"switches per period {fa['grazing']} -> {fb['grazing']}"
            events.append(Event("grazing", ev, detail))
            if log:
                log(f"  grazing at Ω = {ev.omega:.10f}, A0 = {ev.measures['amplitude_0']:.6f} ({detail})")
        orbits.append(nxt)
        cur = nxt
        if it <= 3 and ang < max_angle / 3:
            ds = min(ds * 1.5, ds_max)
        if not (lo <= cur.omega <= hi):
            bound = hi if cur.omega > hi else lo
            last = shoot(orbits[-2].s + (orbits[-1].s - orbits[-2].s) * (bound - orbits[-2].omega)
                         / (orbits[-1].omega - orbits[-2].omega), bound, p)
            last.tangent = cur.tangent
            orbits[-1] = last
            break
    events = [e for e in events if lo <= e.orbit.omega <= hi]
    return Branch(orbits, events, p)


def period_doubling_start(pd: Orbit, eps: float = 1e-3):
    """The T-orbit at a period doubling seen as a 2T-orbit, and the direction of the 2T branch:
    (v, 0) with v the eigenvector of the monodromy for μ = -1 (Kuznetsov §10.3.2; the 2T map's
    Jacobian M² - I has the kernel spanned by v and the T-branch tangent)."""
    mu, V = np.linalg.eig(pd.monodromy)
    i = int(np.argmin(np.abs(mu + 1.0)))
    v = V[:, i].real
    v /= np.linalg.norm(v)
    o2 = make_orbit(pd.s, pd.omega, 2)
    return o2, np.append(v, 0.0)


def rejoin_stop(pd_orbits: list[Orbit]):
    """A `stop` for a 2T branch: it has reached a T-orbit when w = Φ_T(s) - s (zero exactly on the
    T-branch) flips direction between two points; the end is the nearest period doubling of the
    T-branch (seen as a 2T-orbit)."""
    def w(o: Orbit):
        R, _ = residual(o.s, o.omega, 1, False)
        return R

    def stop(cur: Orbit, nxt: Orbit):
        wc = w(cur)
        if np.max(np.abs(wc)) > 1e-7 and wc @ w(nxt) < 0:    # not at the start (a T-orbit)
            pd = min(pd_orbits, key=lambda o: abs(o.omega - nxt.omega) + np.max(np.abs(o.s - nxt.s)))
            return make_orbit(pd.s, pd.omega, 2)
        return None
    return stop
