"""Time marching with compliant (penalty) contacts: scipy `solve_ivp`, one smooth segment at a time.

Between contact switches the right-hand side is linear and smooth; each switch (penetration
s*x[d] - gap(t) crossing zero) is located as a terminal event, and the integration restarts from
the event state with the contact toggled. The kink of the force is therefore never integrated
across and does not limit the accuracy (rtol 1e-10 gives ~1e-10 relative errors).

State: y = [x (n), v (n), Q (m)] with Q_i' = z_i, so that impulses per period are exact to the
integrator's tolerance.
"""
from __future__ import annotations

import time

import numpy as np
from scipy.integrate import solve_ivp

from .model import MarchResult, System, PeriodMonitor


def march_compliant(sys_: System, tol: float = 1e-8, samples: int = 2048, rtol: float = 1e-10,
                    atol: float = 1e-12, method: str = "DOP853", min_periods: int = 3,
                    max_periods: int = 5000, history_per_period: int = 64, x0=None, v0=None) -> MarchResult:
    """Run from rest (or x0, v0) until the periodicity defect between consecutive periods is below
    `tol`; return the last period sampled at `samples` points (see MarchResult)."""
    if not sys_.all_compliant:
        raise ValueError("march_compliant handles compliant contacts only (use rigid.py)")
    cpu0 = time.process_time()
    n, m = sys_.n, sys_.m
    T = sys_.period
    M, C, K = sys_.mass, sys_.damping, sys_.stiffness
    Minv = np.linalg.inv(M)
    dofs = np.array([c.dof for c in sys_.contacts], dtype=int)
    sgn = np.array([c.direction for c in sys_.contacts], dtype=float)
    kc = np.array([c.stiffness for c in sys_.contacts], dtype=float)

    def penetration(t, x):
        return sgn * x[dofs] - sys_.gaps(t)

    def rhs_factory(active):
        act = np.flatnonzero(active)

        def rhs(t, y):
            x, v = y[:n], y[n:2 * n]
            r = sys_.force(t) - C @ v - K @ x
            z = np.zeros(m)
            if act.size:
                pen = sgn[act] * x[dofs[act]] - np.array([sys_.contacts[i].gap_at(sys_.omega, t) for i in act])
                z[act] = kc[act] * pen
                np.add.at(r, dofs[act], -sgn[act] * z[act])
            return np.concatenate([y[n:2 * n], Minv @ r, z])

        return rhs

    def events_factory(active):
        evs = []
        for i in range(m):
            def ev(t, y, i=i):
                return sgn[i] * y[dofs[i]] - sys_.contacts[i].gap_at(sys_.omega, t)

            ev.terminal = True
            ev.direction = -1.0 if active[i] else 1.0
            evs.append(ev)
        return evs

    y = np.zeros(2 * n + m)
    if x0 is not None:
        y[:n] = x0
    if v0 is not None:
        y[n:2 * n] = v0
    pen0 = penetration(0.0, y[:n])
    active = pen0 > 0

    N = samples
    phase = np.arange(N) * (T / N)
    monitor = PeriodMonitor("compliant", N, history_per_period, tol, min_periods, max_periods)
    onsets_last: list = []
    nfev = 0
    nseg = 0
    for p in range(max_periods):
        ta, tb = p * T, (p + 1) * T
        tgrid = ta + phase
        X = np.empty((2 * n + m, N))
        filled = np.zeros(N, dtype=bool)
        onsets = []
        Q0 = y[2 * n:].copy()
        t = ta
        stalls = 0
        while t < tb:
            sol = solve_ivp(rhs_factory(active), (t, tb), y, method=method, rtol=rtol, atol=atol,
                            events=events_factory(active) if m else None, dense_output=True)
            nfev += sol.nfev
            nseg += 1
            if sol.status < 0:
                raise RuntimeError(f"solve_ivp failed: {sol.message}")
            t_end = sol.t[-1]
            sel = (tgrid >= t) & (tgrid <= t_end) & ~filled
            if sel.any():
                X[:, sel] = sol.sol(tgrid[sel])
                filled |= sel
            if sol.status == 1:  # contact switch
                fired = [i for i in range(m) if sol.t_events[i].size]
                t_ev = min(sol.t_events[i][0] for i in fired)
                y = sol.y_events[fired[0]][0].copy()
                for i in fired:
                    if sol.t_events[i][0] <= t_ev + 1e-14 * T:
                        if not active[i]:
                            onsets.append((t_ev - ta, i))
                        active[i] = not active[i]
                stalls = stalls + 1 if t_ev - t < 1e-12 * T else 0
                if stalls > 20:
                    raise RuntimeError(f"compliant marcher stalled at t = {t_ev} (grazing contact?)")
                t = t_ev
            else:
                y = sol.y[:, -1].copy()
                t = tb
        assert filled.all()
        x_cur = X[:n]
        impulse = y[2 * n:] - Q0
        onsets_last = onsets
        if monitor.end_period(p, tgrid, x_cur):
            break
    else:
        raise monitor.not_periodic()

    x, v = X[:n], X[n:2 * n]
    pen = sgn[:, None] * x[dofs] - sys_.gaps(phase + p * T)
    force = kc[:, None] * np.maximum(pen, 0.0)
    a = Minv @ (sys_.force(phase) - C @ v - K @ x - (sys_.B.T @ force))
    return MarchResult(
        method=f"compliant/{method}", system=sys_, t=phase, x=x, v=v, a=a, force=force, impulse=impulse,
        periods=p + 1, cpu_time=time.process_time() - cpu0, **monitor.history(),
        onsets=onsets_last,
        info={"nfev": nfev, "segments": nseg, "rtol": rtol, "atol": atol, "tol": tol})
