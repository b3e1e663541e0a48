"""Exact periodic orbits of a small linear structure with SEVERAL Coulomb friction contacts (rigid,
or Jenkins elements) by an event-driven simulation: independent of the Rust crate (its LCP, its
polish src/analysis/polish/friction/multi.rs). Generalises friction_exact.py (one contact).

    M x'' + C x' + K x = F cos(Ωt) − Σ_i b_i f_i,   f_i = μN_i·sign(b_iᵀv) in slip, |f_i| ≤ μN_i in stick

- a mode is one phase per contact (stick, slip+, slip−);
- stuck rigid contacts hold B_Sᵀv = 0; their forces and the accelerations come from the saddle
  system [M B_S; B_Sᵀ 0][a; f_S] = [r; 0] (r: forcing, springs, dampers, slipping and Jenkins
  forces), solved per mode (numpy inverse);
- a stuck Jenkins element's force is k_t (b_iᵀx − w_i), its slider w_i held;
- between events every mode is linear: y = [x; v; w_1..w_m; cos Ωt; sin Ωt; 1] flows as
  e^{Aτ} y (scipy's expm).
Events: a slip ends at b_iᵀv = 0 (stick if the holding force is within μN_i, else reversal), a
stick at |f_i| = μN_i; found by a sign check on a grid of `substeps` per period and Brent's method
on the closed-form flow; a rigid stick onset removes the velocity along b_i with the impulse of
least kinetic energy (mass-metric projection on the new B_Sᵀv = 0). The steady state: march from
rest until the events repeat, then Newton shooting (scipy's fsolve) on the state at the middle of
the longest interval between events.

Self-check (`python friction_multi_exact.py check`): the 2-DOF chain with rigid friction on both
masses against a DOP853 integration of the regularised law f_i = μN_i tanh(b_iᵀv/ε), ε → 0 (the
difference must fall with ε).
"""
from __future__ import annotations

import json
import os
import sys

for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import numpy as np  # noqa: E402
from scipy.integrate import solve_ivp  # noqa: E402
from scipy.linalg import expm  # noqa: E402
from scipy.optimize import brentq, fsolve  # noqa: E402

STICK, UP, DOWN = 0, 1, -1


class System:
    def __init__(self, M, C, K, F, omega, contacts):
        """contacts: list of (b vector, μN, k_t or None)."""
        self.M, self.C, self.K = (np.asarray(a, float) for a in (M, C, K))
        self.F, self.omega = np.asarray(F, float), omega
        self.b = [np.asarray(c[0], float) for c in contacts]
        self.slip = [c[1] for c in contacts]
        self.kt = [c[2] for c in contacts]
        self.n, self.m = len(self.M), len(contacts)
        self.dim = 2 * self.n + self.m + 3
        self.ic, self.isn, self.i1 = self.dim - 3, self.dim - 2, self.dim - 1
        self.cache = {}
        self.period = 2 * np.pi / omega

    def build(self, mode):
        if mode in self.cache:
            return self.cache[mode]
        n, dim = self.n, self.dim
        r = np.zeros((n, dim))
        r[:, :n] = -self.K
        r[:, n:2 * n] = -self.C
        r[:, self.ic] = self.F
        forces = np.zeros((self.m, dim))
        stuck = []
        for i, ph in enumerate(mode[:self.m]):
            b = self.b[i]
            if ph != STICK:
                r[:, self.i1] -= b * ph * self.slip[i]
                forces[i, self.i1] = ph * self.slip[i]
            elif self.kt[i] is not None:
                kt = self.kt[i]
                r[:, :n] -= kt * np.outer(b, b)
                r[:, 2 * n + i] += kt * b
                forces[i, :n] = kt * b
                forces[i, 2 * n + i] = -kt
            else:
                stuck.append(i)
        self.more_forces(mode, r)
        s = len(stuck)
        saddle = np.zeros((n + s, n + s))
        saddle[:n, :n] = self.M
        for k, i in enumerate(stuck):
            saddle[:n, n + k] = self.b[i]
            saddle[n + k, :n] = self.b[i]
        S = np.linalg.inv(saddle)
        A = np.zeros((dim, dim))
        A[:n, n:2 * n] = np.eye(n)
        A[n:2 * n] = S[:n, :n] @ r
        for k, i in enumerate(stuck):
            forces[i] = S[n + k, :n] @ r
        A[self.ic, self.isn] = -self.omega
        A[self.isn, self.ic] = self.omega
        self.cache[mode] = (A, forces, stuck)
        return self.cache[mode]

    def more_forces(self, mode, r):
        """Adds forces of further mode entries (after the m contacts) to r; none here."""

    def rest_mode(self):
        """The mode the march from rest starts in."""
        return tuple([STICK] * self.m)

    def force(self, mode, i, y):
        return self.build(mode)[1][i] @ y

    def g(self, mode, i, y):
        """> 0 while contact i's phase lasts."""
        ph = mode[i]
        if ph != STICK:
            return ph * (self.b[i] @ y[self.n:2 * self.n])
        return self.slip[i] - abs(self.force(mode, i, y))

    def project(self, mode, y):
        stuck = self.build(mode)[2]
        if not stuck:
            return y
        n = self.n
        B = np.array([self.b[i] for i in stuck]).T
        Minv = np.linalg.inv(self.M)
        v = y[n:2 * n]
        y = y.copy()
        y[n:2 * n] = v - Minv @ B @ np.linalg.solve(B.T @ Minv @ B, B.T @ v)
        return y

    def switch(self, mode, i, y):
        """The mode and state after contact i's phase ends at y."""
        ph = mode[i]
        new = list(mode)
        if ph == STICK:
            new[i] = UP if self.force(mode, i, y) > 0 else DOWN
            return tuple(new), y
        if self.kt[i] is not None:
            new[i] = STICK
            y = y.copy()
            y[2 * self.n + i] = self.b[i] @ y[:self.n] - ph * self.slip[i] / self.kt[i]
            return tuple(new), y
        new[i] = STICK
        ys = self.project(tuple(new), y)
        held = self.force(tuple(new), i, ys)
        if abs(held) <= self.slip[i]:
            return tuple(new), ys
        new[i] = UP if held > 0 else DOWN
        return tuple(new), y

    def augment(self, t, xv, w=None):
        y = np.zeros(self.dim)
        y[:2 * self.n] = xv
        if w is not None:
            y[2 * self.n:2 * self.n + self.m] = w
        y[self.ic], y[self.isn], y[self.i1] = np.cos(self.omega * t), np.sin(self.omega * t), 1.0
        return y

    def march(self, t0, mode, y, duration, substeps, record=False):
        """Flows (t0, mode, y) for `duration`; returns the end mode and state, and the events
        [(t, contact, new phase)] and segments [(t, mode, y)] if `record`."""
        h = self.period / substeps
        t, t_end = t0, t0 + duration
        events, segs = [], [(t0, mode, y.copy())]
        while t_end - t > 1e-14 * self.period:
            dh = min(h, t_end - t)
            A = self.build(mode)[0]
            key = (mode, dh)
            if key not in self.cache:
                self.cache[key] = expm(A * dh)
            yn = self.cache[key] @ y
            ended = [i for i in range(len(mode)) if self.g(mode, i, yn) < 0]
            if not ended:
                t, y = t + dh, yn
                continue
            best = None
            for i in ended:
                f = lambda tau, i=i: self.g(mode, i, expm(A * tau) @ y)  # noqa: E731
                if f(0.0) <= 0:
                    tau = 0.0
                else:
                    tau = brentq(f, 0.0, dh, xtol=1e-15, rtol=4 * np.finfo(float).eps, maxiter=200)
                if best is None or tau < best[0]:
                    best = (tau, i)
            tau, i = best
            ye = expm(A * tau) @ y
            new, ye = self.switch(mode, i, ye)
            t, y = t + tau, ye
            if new != mode:
                events.append((t, i, new[i]))
                mode = new
                segs.append((t, mode, y.copy()))
            elif tau == 0.0:
                t, y = t + dh, yn  # a grazing touch: nothing changes
        return (mode, y, events, segs) if record else (mode, y)


def steady(sys_, substeps=2000, periods=800, tol=1e-13):
    """The periodic orbit: march from rest until a period's events repeat, then shooting."""
    T = sys_.period
    mode = sys_.rest_mode()
    y = sys_.augment(0.0, np.zeros(2 * sys_.n))
    prev = None
    t = 0.0
    for _ in range(periods):
        mode, y, ev, _ = sys_.march(t, mode, y, T, 400, record=True)
        evr = [(e[0] - t, e[1], e[2]) for e in ev]  # times within the period, in [0, T)
        t += T
        if prev is not None and len(prev) == len(evr) and all(
                a[1] == b[1] and a[2] == b[2] and abs(a[0] - b[0]) < 1e-6 * T for a, b in zip(prev, evr)):
            break
        prev = evr
    # Start in the middle of the longest interval between events (mode and state from the march).
    times = sorted(e[0] for e in prev or [])
    mid = 0.0
    if times:
        gaps = [((times[(k + 1) % len(times)] - times[k]) % T or T, k) for k in range(len(times))]
        gap, k = max(gaps)
        mid = (times[k] + gap / 2) % T
    mode, y = sys_.march(t, mode, y, mid, 400)
    tt = t + mid
    start_mode = mode
    free = [i for i in range(sys_.m) if start_mode[i] == STICK and sys_.kt[i] is not None]
    n2 = 2 * sys_.n

    def unpack(u):
        yy = y.copy()
        yy[:n2] = u[:n2]
        for k, i in enumerate(free):
            yy[n2 + i] = u[n2 + k]
        yy[sys_.ic], yy[sys_.isn] = np.cos(sys_.omega * tt), np.sin(sys_.omega * tt)
        return yy

    def residual(u):
        m2, ye = sys_.march(tt, start_mode, unpack(u), T, substeps)
        if m2 != start_mode:
            return np.full(len(u), 1e3)
        return np.concatenate([ye[:n2] - u[:n2], [ye[n2 + i] - u[n2 + k] for k, i in enumerate(free)]])

    u0 = np.concatenate([y[:n2], [y[n2 + i] for i in free]])
    u = fsolve(residual, u0, xtol=tol, full_output=False)
    y0 = unpack(u)
    _, _, events, segs = sys_.march(tt, start_mode, y0, T, substeps, record=True)
    return Orbit(sys_, tt, segs, events, float(np.max(np.abs(residual(u)))))


class Orbit:
    def __init__(self, sys_, start, segs, events, residual):
        self.s, self.start, self.segs, self.events, self.residual = sys_, start, segs, events, residual

    def at(self, t):
        T = self.s.period
        tt = self.start + (t - self.start) % T
        seg = max((sg for sg in self.segs if sg[0] <= tt), key=lambda sg: sg[0])
        return seg[1], expm(self.s.build(seg[1])[0] * (tt - seg[0])) @ seg[2]

    def displacement(self, t):
        return self.at(t)[1][:self.s.n]

    def stuck_fraction(self, i):
        T = self.s.period
        ends = [sg[0] for sg in self.segs] + [self.start + T]
        return sum(ends[k + 1] - ends[k] for k, sg in enumerate(self.segs) if sg[1][i] == STICK) / T


def chain(omega, slips=(0.25, 0.15), kts=(None, None)):
    """The 2-DOF chain of tests/friction.rs with friction on both masses."""
    M = np.diag([1.0, 0.5])
    C = np.array([[0.06, -0.02], [-0.02, 0.02]])
    K = np.array([[2.0, -1.0], [-1.0, 1.0]])
    return System(M, C, K, [1.0, 0.0], omega, [([0.0, 1.0], slips[0], kts[0]), ([1.0, 0.0], slips[1], kts[1])])


def chain3(omega, slips=(0.35, 0.3), kt=2.0):
    """A 3-DOF chain: rigid Coulomb on mass 1, a Jenkins element on mass 3."""
    M = np.diag([1.0, 0.8, 0.6])
    C = np.array([[0.05, -0.02, 0.0], [-0.02, 0.04, -0.02], [0.0, -0.02, 0.03]])
    K = np.array([[2.0, -1.0, 0.0], [-1.0, 2.0, -1.0], [0.0, -1.0, 1.5]])
    return System(M, C, K, [1.0, 0.0, 0.3], omega, [([1.0, 0.0, 0.0], slips[0], None), ([0.0, 0.0, 1.0], slips[1], kt)])


def regularised(sys_, orbit, eps, periods=40):
    """DOP853 on the regularised law (rigid contacts only) from the exact orbit's state at t = 0."""
    n = sys_.n
    Minv = np.linalg.inv(sys_.M)

    def rhs(t, z):
        x, v = z[:n], z[n:]
        f = sum(b * s * np.tanh((b @ v) / eps) for b, s in zip(sys_.b, sys_.slip))
        return np.concatenate([v, Minv @ (sys_.F * np.cos(sys_.omega * t) - sys_.K @ x - sys_.C @ v - f)])

    y0 = orbit.at(0.0)[1][:2 * n]
    T = sys_.period
    ts = np.linspace((periods - 1) * T, periods * T, 97, endpoint=False)
    sol = solve_ivp(rhs, (0, periods * T), y0, method="DOP853", rtol=1e-11, atol=1e-13, t_eval=ts)
    exact = np.array([orbit.displacement(t) for t in ts]).T
    return np.max(np.abs(sol.y[:n] - exact)) / np.max(np.abs(exact))


def main():
    if len(sys.argv) > 1 and sys.argv[1] == "check":
        for omega, slips in ((0.8, (0.25, 0.15)), (1.2, (0.25, 0.15)), (0.8, (0.6, 0.5))):
            s = chain(omega, slips)
            o = steady(s)
            fr = [round(o.stuck_fraction(i), 4) for i in range(s.m)]
            print(f"chain Ω = {omega}, μN = {slips}: {len(o.events)} events, stuck fractions {fr}, residual {o.residual:.1e}")
            for eps in (1e-2, 1e-3, 1e-4):
                print(f"  DOP853, f = μN tanh(v/ε), ε = {eps:.0e}: max |x − x_exact| / max|x| = {regularised(s, o, eps):.2e}")
        return
    # Reference numbers for tests/friction_polish.rs: x at t_j = j·T/16, stuck fractions.
    cases = {
        "chain, μN = 0.6 on m2 and 0.5 on m1, Ω = 0.8": chain(0.8, (0.6, 0.5)),
        "chain3, Coulomb 0.35 on m1, Jenkins 0.3 (k_t = 2) on m3, Ω = 0.6": chain3(0.6),
        "chain3, Ω = 1.3": chain3(1.3),
    }
    out = {}
    for name, s in cases.items():
        o = steady(s)
        T = s.period
        out[name] = {
            "events": len(o.events),
            "residual": o.residual,
            "x": [list(o.displacement(j * T / 16)) for j in range(16)],
            "stuck_fraction": [o.stuck_fraction(i) for i in range(s.m)],
        }
        print(name, json.dumps(out[name]))


if __name__ == "__main__":
    main()
