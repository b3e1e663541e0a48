"""Long time integration of NLvib's Example 03, two ways.

- `march`: the exact piecewise-linear flow of flow.py, iterated period by period (stroboscopic
  map y_n = y(nT)); stops when y_n is pT-periodic (p = 1…4) to `tol`, or after max_periods.
- `ivp_flow`: scipy's solve_ivp (DOP853, rtol 1e-12, atol 1e-12) with the switch x0 = gap as a
  terminal event (the kink is never integrated across). It shares no code with flow.py and is
  the independent check of the exact flow (tests).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.integrate import solve_ivp

from .flow import DAMP, FORCE, GAP, K_LIN, KC, Nlvib03


@dataclass
class MarchOutcome:
    omega: float
    kind: str                 # "T", "2T", "3T", "4T" (periodic to tol) or "nonperiodic"
    periods: int              # periods integrated
    y: np.ndarray             # last stroboscopic state y(nT)
    defect: float             # ‖y_n - y_{n-p}‖∞ for the detected p (p = 1 when nonperiodic)
    amplitude_0: float        # half peak-to-peak of x0 over the last 4 periods
    amplitude_1: float
    strobe_spread: float      # max - min of x0(nT) over the last 200 periods (0 for T-periodic)

    @property
    def period_multiple(self) -> int:
        return int(self.kind[:-1] or 1) if self.kind != "nonperiodic" else 0


def march(omega: float, y0, max_periods: int = 4000, tol: float = 1e-10, p_max: int = 4) -> MarchOutcome:
    sysm = Nlvib03(omega)
    y = np.asarray(y0, dtype=float).copy()
    hist = [y.copy()]
    kind, defect = "nonperiodic", np.inf
    for n in range(1, max_periods + 1):
        y = sysm.integrate(0.0, y, sysm.T).y
        hist.append(y.copy())
        if len(hist) > 200:
            hist.pop(0)
        for p in range(1, p_max + 1):
            if len(hist) > p:
                d = float(np.max(np.abs(hist[-1] - hist[-1 - p])))
                if p == 1:
                    defect = d
                # pT only when the p shifts are distinct points (d_1 > 1e-6): a T-orbit whose
                # multipliers turn by ~2π/p per period closes its pT-defect first
                if d < tol and (p == 1 or defect > 1e-6):
                    kind, defect = ("T" if p == 1 else f"{p}T"), d
                    break
        if kind != "nonperiodic":
            break
    res = sysm.integrate(0.0, y, 4 * sysm.T)
    a = [0.5 * np.subtract(*sysm.extrema(res.segments, i)[::-1]) for i in range(2)]
    x0s = np.array([h[0] for h in hist])
    spread = 0.0 if kind != "nonperiodic" else float(x0s.max() - x0s.min())
    return MarchOutcome(omega, kind, n, y, defect, float(a[0]), float(a[1]), spread)


def _rhs(omega: float):
    def f(t, y):
        x, v = y[:2], y[2:]
        a = -K_LIN @ x - DAMP @ v
        a[0] -= KC * max(0.0, x[0] - GAP)
        a[1] += FORCE * np.cos(omega * t)
        return np.concatenate([v, a])
    return f


def ivp_flow(omega: float, y0, t_end: float, rtol: float = 1e-12, atol: float = 1e-12) -> np.ndarray:
    """y(t_end) from y(0) = y0 by solve_ivp, restarting at each x0 = gap crossing."""
    f = _rhs(omega)
    y = np.asarray(y0, dtype=float).copy()
    t = 0.0

    def ev(t, y):
        return y[0] - GAP
    ev.terminal = True

    while t < t_end:
        sol = solve_ivp(f, (t, t_end), y, method="DOP853", rtol=rtol, atol=atol, events=ev)
        if sol.status == 1 and sol.t_events[0].size and sol.t_events[0][0] > t + 1e-12:
            t = float(sol.t_events[0][0])
            y = sol.y_events[0][0].copy()
            # step just past the switch with the new regime's field (avoids re-triggering at t)
            sol2 = solve_ivp(f, (t, min(t + 1e-9, t_end)), y, method="DOP853", rtol=rtol, atol=atol)
            t, y = float(sol2.t[-1]), sol2.y[:, -1].copy()
        else:
            t, y = float(sol.t[-1]), sol.y[:, -1].copy()
            if sol.status == 0:
                break
    return y
