"""Explicit central differences with forward-increment Lagrange multipliers (src/formulation.md §5; Carpenter,
Taylor & Katona 1991), in the user-facing signs (clearance c = gap - B x >= 0, force z >= 0):

    Ŵ = (M/h² + C/(2h))^-1
    predictor   x^p_{n+1} = Ŵ [ f_n - (K - 2M/h²) x_n - (M/h² - C/(2h)) x_{n-1} - B_s^T z^s_n ]
    predicted clearance c^p = gap(t_{n+1}) - B_F x^p_{n+1}
    LCP         w = (B_F Ŵ B_F^T + diag(1/k_c)) z + c^p,  z >= 0, w >= 0, z.w = 0
    corrector   x_{n+1} = x^p_{n+1} - Ŵ B_F^T z_n

i.e. M (x_{n+1} - 2x_n + x_{n-1})/h² + C (x_{n+1} - x_{n-1})/(2h) + K x_n + B^T z_n = f_n, where
each force sample z_n is paired with the clearance at t_{n+1} ("forward" pairing) for rigid
contacts (1/k_c = 0) and for compliant contacts when pairing="forward". With pairing="same" a
compliant contact carries the explicit penalty force z_n = k_c max(0, -c(x_n, t_n)) instead
(B_s rows above). The LCP is solved on the predicted-active set {c^p < 0} by enumeration (up to 8
simultaneously active contacts), growing the set if the correction pushes another contact into
its obstacle (model.solve_contact_lcp); the total number of contacts is not limited.

The steady state of this recursion is a k-periodic sequence satisfying exactly the periodic "cds"
equations of the notes (§2) with the same pairing, which is why it is also a discrete reference.
Stable for h < 2/ω_max (ω_max with compliant contacts closed).
"""
from __future__ import annotations

import time

import numpy as np

from .model import MarchResult, System, PeriodMonitor, solve_contact_lcp


def march_cds(sys_: System, steps: int, pairing: str = "forward", tol: float = 1e-10, min_periods: int = 3,
              max_periods: int = 20000, history_per_period: int = 64, x0=None, v0=None) -> MarchResult:
    """March `steps` steps per period from rest until the periodicity defect is below `tol`.

    pairing: "forward" (every contact's force z_n is paired with the clearance at t_{n+1}) or "same"
    (compliant contacts explicit at t_n; rigid contacts are always forward, the same-instant
    pairing being ill-posed for them)."""
    if pairing not in ("forward", "same"):
        raise ValueError("pairing must be 'forward' or 'same'")
    cpu0 = time.process_time()
    n, m = sys_.n, sys_.m
    T = sys_.period
    k = int(steps)
    h = T / k
    wmax = sys_.max_frequency()
    if h * wmax >= 2.0:
        raise ValueError(f"central differences unstable: h*ω_max = {h * wmax:.3f} >= 2 (use more steps)")
    M, C, K = sys_.mass, sys_.damping, sys_.stiffness
    W = np.linalg.inv(M / h**2 + C / (2 * h))
    A1 = W @ (2 * M / h**2 - K)
    A0 = -W @ (M / h**2 - C / (2 * h))
    tj = np.arange(k) * h
    Wf = (W @ sys_.force(tj)).T.copy()  # (k, n)
    B = sys_.B
    rigid = np.array([c.rigid for c in sys_.contacts], dtype=bool)
    fwd = rigid | (pairing == "forward")
    same = ~fwd
    Fi = np.flatnonzero(fwd)
    Si = np.flatnonzero(same)
    BF, BS = B[Fi], B[Si]
    WBF = W @ BF.T
    WBS = W @ BS.T
    compl = np.array([0.0 if c.rigid else 1.0 / c.stiffness for c in sys_.contacts])
    GF = BF @ WBF + np.diag(compl[Fi])
    kS = np.array([sys_.contacts[i].stiffness for i in Si], dtype=float)
    gaps = sys_.gaps(tj)  # (m, k): gap(t_j)
    gF_next = np.roll(gaps[Fi], -1, axis=1).T.copy()  # (k, |F|): gap(t_{j+1})
    gS = gaps[Si].T.copy()

    x = np.zeros(n) if x0 is None else np.asarray(x0, dtype=float).copy()
    v = np.zeros(n) if v0 is None else np.asarray(v0, dtype=float).copy()
    a0 = np.linalg.solve(M, sys_.force(0.0) - C @ v - K @ x)
    xm = x - h * v + 0.5 * h * h * a0

    monitor = PeriodMonitor("cds", k, history_per_period, tol, min_periods, max_periods)
    lcp_calls = 0
    for p in range(max_periods):
        X = np.empty((n, k))
        Z = np.zeros((m, k))
        for j in range(k):
            X[:, j] = x
            xp = A1 @ x + A0 @ xm + Wf[j]
            if Si.size:
                pen = BS @ x - gS[j]
                if np.any(pen > 0):
                    zs = kS * np.maximum(pen, 0.0)
                    xp = xp - WBS @ zs
                    Z[Si, j] = zs
            if Fi.size:
                cp = gF_next[j] - BF @ xp
                if np.any(cp < 0):
                    zf = solve_contact_lcp(GF, cp)
                    lcp_calls += 1
                    xp = xp - WBF @ zf
                    Z[Fi, j] = zf
            xm, x = x, xp
        if monitor.end_period(p, p * T + tj, X):
            break
    else:
        raise monitor.not_periodic()
    # periodic central differences of the last period (the engine applies the same symbols)
    Xp, Xm = np.roll(X, -1, axis=1), np.roll(X, 1, axis=1)
    V = (Xp - Xm) / (2 * h)
    A = (Xp - 2 * X + Xm) / h**2
    impulse = h * Z.sum(axis=1)
    onsets = []
    for i in range(m):
        on = np.flatnonzero((Z[i] > 0) & (np.roll(Z[i], 1) == 0))
        onsets += [(float(tj[j]), i) for j in on]
    onsets.sort()
    return MarchResult(
        method=f"cds/{pairing}", system=sys_, t=tj, x=X, v=V, a=A, force=Z, impulse=impulse, periods=p + 1,
        cpu_time=time.process_time() - cpu0, **monitor.history(),
        onsets=onsets, steps=k,
        info={"lcp_calls": lcp_calls, "tol": tol, "h_omega_max": h * wmax})
