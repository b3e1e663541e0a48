"""Event-driven time marching with rigid contacts, plastic impacts (restitution 0) and sticking.

Modes: each contact is either *free* (clearance c_i = gap_i(t) - B_i x > 0) or *stuck* (c_i = 0
held by a compressive force z_i >= 0). In a mode the dynamics are smooth:

    [M  B_S^T] [a  ]   [f - C v - K x]
    [B_S   0 ] [z_S] = [gap_S''(t)   ]        (B_S x = gap_S(t) kept exactly)

and are integrated with `solve_ivp` (DOP853) with terminal events:
  - free contact:  clearance c_i(t) crossing zero downward        -> impact;
  - stuck contact: force z_i(t) crossing zero downward            -> release.

Impact (plastic): all closed contacts (stuck ones and the impacting ones) receive impulses
P >= 0 with post-impact approach velocities u+ = u- + G P >= 0, P.u+ = 0, G = B_C M^-1 B_C^T
(a small LCP; in 1-DOF simply v+ = gap'). Velocities jump by -M^-1 B_C^T P. After an impact the
new stuck set solves the force LCP c'' = gap'' - B M^-1 (f - C v - K x) + G z >= 0, z >= 0.

State y = [x, v, Q] with Q_i' = z_i; impact impulses are added to Q, so Q gives the total impulse
per period (impacts + sticking) to the integrator's tolerance.
"""
from __future__ import annotations

import time

import numpy as np
from scipy.integrate import solve_ivp

from .model import MarchResult, System, PeriodMonitor, solve_lcp_enum


def march_rigid(sys_: System, tol: float = 1e-8, samples: int = 2048, rtol: float = 1e-10,
                atol: float = 1e-12, method: str = "DOP853", min_periods: int = 3,
                max_periods: int = 5000, history_per_period: int = 64, x0=None, v0=None) -> MarchResult:
    if not sys_.all_rigid:
        raise ValueError("march_rigid handles rigid contacts only (use compliant.py)")
    cpu0 = time.process_time()
    n, m = sys_.n, sys_.m
    T = sys_.period
    om = sys_.omega
    M, C, K = sys_.mass, sys_.damping, sys_.stiffness
    Minv = np.linalg.inv(M)
    B = sys_.B
    G = B @ Minv @ B.T
    dofs = np.array([c.dof for c in sys_.contacts], dtype=int)
    sgn = np.array([c.direction for c in sys_.contacts], dtype=float)
    scale_x = 1.0  # length scale for "closed" tests, updated from the gaps
    if m:
        scale_x = max(1.0, float(np.max(np.abs([c.gap for c in sys_.contacts]))))
    eps_c = 1e-10 * scale_x  # clearance considered zero at an event

    def gap1(i, t, d=0):
        return sys_.contacts[i].gap_at(om, t, d)

    def accel_force(t, x, v, stuck_idx):
        """(a, z_S) in a mode with stuck contacts stuck_idx."""
        r = sys_.force(t) - C @ v - K @ x
        if stuck_idx.size == 0:
            return Minv @ r, np.zeros(0)
        BS = B[stuck_idx]
        k = stuck_idx.size
        A = np.zeros((n + k, n + k))
        A[:n, :n] = M
        A[:n, n:] = BS.T
        A[n:, :n] = BS
        rhs = np.concatenate([r, [gap1(i, t, 2) for i in stuck_idx]])
        sol = np.linalg.solve(A, rhs)
        return sol[:n], sol[n:]

    def rhs_factory(stuck):
        sidx = np.flatnonzero(stuck)

        def rhs(t, y):
            x, v = y[:n], y[n:2 * n]
            a, zs = accel_force(t, x, v, sidx)
            dQ = np.zeros(m)
            dQ[sidx] = zs
            return np.concatenate([v, a, dQ])

        return rhs

    def events_factory(stuck):
        sidx = np.flatnonzero(stuck)
        evs = []
        for i in range(m):
            if stuck[i]:
                pos = int(np.flatnonzero(sidx == i)[0])

                def ev(t, y, pos=pos):
                    return accel_force(t, y[:n], y[n:2 * n], sidx)[1][pos]
            else:
                def ev(t, y, i=i):
                    return gap1(i, t) - sgn[i] * y[dofs[i]]
            ev.terminal = True
            ev.direction = -1.0
            evs.append(ev)
        return evs

    def project(t, y, stuck):
        """Put stuck DOFs exactly on their obstacles (removes integration drift)."""
        for i in np.flatnonzero(stuck):
            y[dofs[i]] = sgn[i] * gap1(i, t)
            y[n + dofs[i]] = sgn[i] * gap1(i, t, 1)

    def stick_set(t, y, closed):
        """Force LCP on the closed contacts with zero approach velocity: which ones stick."""
        cidx = np.flatnonzero(closed)
        stuck = np.zeros(m, dtype=bool)
        if cidx.size == 0:
            return stuck
        x, v = y[:n], y[n:2 * n]
        a_free = Minv @ (sys_.force(t) - C @ v - K @ x)
        q = np.array([gap1(i, t, 2) for i in cidx]) - B[cidx] @ a_free  # c'' without contact forces
        z = solve_lcp_enum(G[np.ix_(cidx, cidx)], q)
        stuck[cidx[z > 0]] = True
        return stuck

    def impact(t, y, stuck):
        """Plastic impact at t; returns (impulses (m,), new stuck mask)."""
        x, v = y[:n], y[n:2 * n]
        clear = np.array([gap1(i, t) - sgn[i] * x[dofs[i]] for i in range(m)])
        u = np.array([gap1(i, t, 1) - sgn[i] * v[dofs[i]] for i in range(m)])  # clearance rate
        closed = stuck | (np.abs(clear) <= eps_c)
        cidx = np.flatnonzero(closed)
        P = np.zeros(m)
        if cidx.size:
            P[cidx] = solve_lcp_enum(G[np.ix_(cidx, cidx)], u[cidx])
            y[n:2 * n] = v - Minv @ (B.T @ P)
        # contacts closed with zero clearance rate after the impact may stick
        v = y[n:2 * n]
        u = np.array([gap1(i, t, 1) - sgn[i] * v[dofs[i]] for i in range(m)])
        uscale = max(1.0, float(np.max(np.abs(v))))
        resting = closed & (np.abs(u) <= 1e-9 * uscale)
        for i in np.flatnonzero(resting):  # exactly on the obstacle, exactly at its speed
            y[dofs[i]] = sgn[i] * gap1(i, t)
            y[n + dofs[i]] = sgn[i] * gap1(i, t, 1)
        return P, stick_set(t, y, resting)

    y = np.zeros(2 * n + m)
    if x0 is not None:
        y[:n] = x0
    if v0 is not None:
        y[n:2 * n] = v0
    if m and np.any(sys_.clearance(0.0, y[:n]) < -eps_c):
        raise ValueError("initial state penetrates an obstacle")
    stuck = np.zeros(m, dtype=bool)

    N = samples
    phase = np.arange(N) * (T / N)
    monitor = PeriodMonitor("rigid", N, history_per_period, tol, min_periods, max_periods)
    nfev = nseg = nimp = 0
    for p in range(max_periods):
        ta, tb = p * T, (p + 1) * T
        tgrid = ta + phase
        X = np.empty((2 * n + m, N))
        S = np.zeros((m, N), dtype=bool)  # stuck flags at the samples
        filled = np.zeros(N, dtype=bool)
        impacts, onsets = [], []
        Q0 = y[2 * n:].copy()
        t = ta
        stalls = 0
        while t < tb:
            project(t, y, stuck)
            sol = solve_ivp(rhs_factory(stuck), (t, tb), y, method=method, rtol=rtol, atol=atol,
                            events=events_factory(stuck) if m else None, dense_output=True)
            nfev += sol.nfev
            nseg += 1
            if sol.status < 0:
                raise RuntimeError(f"solve_ivp failed: {sol.message}")
            t_end = sol.t[-1]
            sel = (tgrid >= t) & (tgrid < t_end) & ~filled
            if sel.any():
                X[:, sel] = sol.sol(tgrid[sel])
                S[:, sel] = stuck[:, None]
                filled |= sel
            if sol.status == 1:
                fired = [i for i in range(m) if sol.t_events[i].size]
                t_ev = min(sol.t_events[i][0] for i in fired)
                y = sol.y_events[fired[0]][0].copy()
                releases = [i for i in fired if stuck[i]]
                if releases:  # z_i = 0 here, the other stuck forces are unaffected
                    for i in releases:
                        stuck[i] = False
                else:
                    P, stuck = impact(t_ev, y, stuck)
                    y[2 * n:] += P
                    nimp += 1
                    for i in np.flatnonzero(P > 0):
                        impacts.append((t_ev - ta, int(i), float(P[i])))
                    for i in fired:
                        onsets.append((t_ev - ta, int(i)))
                stalls = stalls + 1 if t_ev - t < 1e-12 * T else 0
                if stalls > 50:
                    raise RuntimeError(f"rigid marcher stalled at t = {t_ev}")
                t = t_ev
            else:
                y = sol.y[:, -1].copy()
                t = tb
        # samples exactly at an event time that ended the period are filled from the last segment
        if not filled.all():
            X[:, ~filled] = y[:, None]
            S[:, ~filled] = stuck[:, None]
        x_cur = X[:n]
        impulse = y[2 * n:] - Q0
        if monitor.end_period(p, tgrid, x_cur):
            break
    else:
        raise monitor.not_periodic()

    x, v = X[:n], X[n:2 * n]
    a = np.empty_like(x)
    force = np.zeros((m, N))
    for j in range(N):
        sidx = np.flatnonzero(S[:, j])
        a[:, j], zs = accel_force(phase[j], x[:, j], v[:, j], sidx)
        force[sidx, j] = zs
    return MarchResult(
        method=f"rigid/{method}", system=sys_, t=phase, x=x, v=v, a=a, force=force, impulse=impulse,
        periods=p + 1, cpu_time=time.process_time() - cpu0, **monitor.history(),
        impacts=impacts,
        onsets=onsets, info={"nfev": nfev, "segments": nseg, "impacts": nimp, "rtol": rtol, "atol": atol,
                             "tol": tol})
