"""Exact periodic orbits of a small linear structure with one Coulomb friction contact (rigid, or a
Jenkins element), by an event-driven simulation: independent of the Rust crate (its LCP, its polish
and its own event-driven simulation in src/exact/friction.rs).

    M x'' + C x' + K x = F cos(Ωt) − e_d f,     f = μN·sign(v_s) in slip, |f| < μN in stick

- rigid Coulomb: the slider is x_d itself; stick holds v_d = 0 and f is the reaction of the
  constrained system [M e_d; e_dᵀ 0] [a; f] = [F cos Ωt − Kx − Cv; 0];
- Jenkins: f = k_t (x_d − w), the slider w fixed in stick, moving (f = ±μN) in slip.
Between events every phase is linear with harmonic forcing; the state is augmented to
y = [x; v; w; cos Ωt; sin Ωt; 1] so that each phase flows as y(t+τ) = e^{Aτ} y(t) (scipy's expm).
Events (slip end at v_d = 0, stick end at |f| = μN) are found by a sign check on a grid of
`substeps` per period and Brent's method on the closed-form flow. The steady state: march from rest
until the period map repeats to `march_tol`, then Newton shooting (scipy's fsolve) on the state at a
time inside the longest phase, to `tol`.
"""
from __future__ import annotations

import os
from dataclasses import dataclass

for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import numpy as np  # noqa: E402
from scipy.linalg import expm  # noqa: E402
from scipy.optimize import brentq, fsolve, minimize_scalar  # noqa: E402

STICK, SLIP_UP, SLIP_DOWN = 0, 1, 2


@dataclass
class FrictionSystem:
    M: np.ndarray
    C: np.ndarray
    K: np.ndarray
    F: np.ndarray        # amplitudes of F cos Ωt per DOF
    omega: float
    dof: int
    slip_force: float    # μN
    kt: float | None = None   # Jenkins tangential stiffness; None: rigid Coulomb

    @property
    def n(self) -> int:
        return len(self.M)

    @property
    def period(self) -> float:
        return 2 * np.pi / self.omega


class Flows:
    """The phases' augmented matrices and event forms."""

    def __init__(self, s: FrictionSystem):
        n, d = s.n, s.dof
        self.s, self.n, self.dim = s, n, 2 * n + 4
        iw, ic, isn, i1 = 2 * n, 2 * n + 1, 2 * n + 2, 2 * n + 3
        self.iw, self.ic, self.isn = iw, ic, isn
        # r(y) = F cos Ωt − K x − C v as a linear form of y (n rows).
        r = np.zeros((n, self.dim))
        r[:, :n] = -s.K
        r[:, n:2 * n] = -s.C
        r[:, ic] = s.F
        Minv = np.linalg.inv(s.M)
        e = np.zeros(n)
        e[d] = 1.0
        mats = []
        for phase in (STICK, SLIP_UP, SLIP_DOWN):
            A = np.zeros((self.dim, self.dim))
            A[:n, n:2 * n] = np.eye(n)
            A[ic, isn] = -s.omega
            A[isn, ic] = s.omega
            if phase == STICK and s.kt is None:
                saddle = np.zeros((n + 1, n + 1))
                saddle[:n, :n] = s.M
                saddle[:n, n] = e
                saddle[n, :n] = e
                S = np.linalg.inv(saddle)
                A[n:2 * n] = S[:n, :n] @ r
                self.stick_force = S[n, :n] @ r
            elif phase == STICK:
                rr = r.copy()
                rr[d, d] -= s.kt
                rr[d, iw] += s.kt
                A[n:2 * n] = Minv @ rr
                self.stick_force = np.zeros(self.dim)
                self.stick_force[d] = s.kt
                self.stick_force[iw] = -s.kt
            else:
                sign = 1.0 if phase == SLIP_UP else -1.0
                rr = r.copy()
                rr[d, i1] -= sign * s.slip_force
                A[n:2 * n] = Minv @ rr
            mats.append(A)
        self.A = mats
        self.h = None
        self.step_maps = None

    def set_step(self, h: float):
        self.h = h
        self.step_maps = [expm(A * h) for A in self.A]

    def flow(self, phase: int, y: np.ndarray, tau: float) -> np.ndarray:
        return expm(self.A[phase] * tau) @ y

    def event(self, phase: int, y: np.ndarray) -> float:
        """> 0 while the phase lasts."""
        vd = y[self.n + self.s.dof]
        if phase == SLIP_UP:
            return vd
        if phase == SLIP_DOWN:
            return -vd
        return self.s.slip_force - abs(self.stick_force @ y)

    def next_phase(self, phase: int, y: np.ndarray) -> int:
        """The phase after `phase` ends at y (y adjusted in place: a stuck velocity is 0, a
        Jenkins slider placed so that f = ±μN at the stick onset)."""
        s, n, d = self.s, self.n, self.s.dof
        if phase == STICK:
            return SLIP_UP if self.stick_force @ y > 0 else SLIP_DOWN
        sign = 1.0 if phase == SLIP_UP else -1.0
        y[n + d] = 0.0
        if s.kt is not None:
            y[self.iw] = y[d] - sign * s.slip_force / s.kt
            return STICK
        f = self.stick_force @ y
        if abs(f) < s.slip_force:
            return STICK
        return SLIP_UP if f > 0 else SLIP_DOWN

    def initial_phase(self, y: np.ndarray) -> int:
        """The phase of a state y (a slip keeps its velocity's sign; at v_d = 0 as next_phase)."""
        vd = y[self.n + self.s.dof]
        if self.s.kt is not None:
            if abs(self.stick_force @ y) < self.s.slip_force:
                return STICK
            return SLIP_UP if self.stick_force @ y > 0 else SLIP_DOWN
        if vd > 0:
            return SLIP_UP
        if vd < 0:
            return SLIP_DOWN
        return self.next_phase(SLIP_UP, y)


def _march(fl, t0: float, y: np.ndarray, phase: int, duration: float, record=False):
    """Flow from (t0, y, phase) for `duration` on a grid of `duration/fl.h` steps; returns the end
    state and phase, and the segments [(start, phase, y)] if `record`. `fl` is any flows object with
    `h`, `step_maps`, `flow`, `event` and `next_phase` (also coupled_exact.Flows)."""
    segs = [(t0, phase, y.copy())] if record else None
    t = t0
    steps = int(round(duration / fl.h))
    events = 0
    for i in range(steps):
        end = t0 + (i + 1) * fl.h
        while True:
            full = abs((end - t) - fl.h) < 1e-15 * max(1.0, end)
            y1 = fl.step_maps[phase] @ y if full else fl.flow(phase, y, end - t)
            if fl.event(phase, y1) > 0:
                y, t = y1, end
                break
            g = lambda tau: fl.event(phase, fl.flow(phase, y, tau))  # noqa: E731
            tau_end = end - t
            # The first sign change on (0, tau_end]: refine on a sub-grid (an event can start at 0).
            lo, hi = 0.0, tau_end
            for j in range(1, 9):
                tj = tau_end * j / 8
                if g(tj) <= 0:
                    hi = tj
                    break
                lo = tj
            if lo > 0 or g(0.0) > 0:
                tau = brentq(g, lo, hi, xtol=1e-16, rtol=8.9e-16, maxiter=200)
            else:
                # The phase starts on its event (a slip from v_d = 0): bisect, g > 0 just after 0.
                a, b = 0.0, hi
                for _ in range(60):
                    m = 0.5 * (a + b)
                    if g(m) > 0:
                        a = m
                    else:
                        b = m
                tau = b
            y = fl.flow(phase, y, tau)
            t += tau
            phase = fl.next_phase(phase, y)
            events += 1
            if record:
                segs.append((t, phase, y.copy()))
            if events > 50 * steps:
                raise RuntimeError("the event-driven simulation chatters")
    return y, phase, segs


@dataclass
class FrictionOrbit:
    flows: Flows
    segments: list      # [(start, phase, y)] over [t0, t0 + T)
    t0: float
    periods_marched: int
    shooting_residual: float

    @property
    def period(self) -> float:
        return self.flows.s.period

    def state(self, t: float) -> np.ndarray:
        T = self.period
        t = self.t0 + (t - self.t0) % T
        starts = [s[0] for s in self.segments]
        i = max(0, int(np.searchsorted(starts, t, side="right")) - 1)
        start, phase, y = self.segments[i]
        return self.flows.flow(phase, y, t - start)

    def displacement(self, times) -> np.ndarray:
        """x(t) at each time: array (len(times), n)."""
        return np.array([self.state(t)[: self.flows.n] for t in times])

    def amplitude(self, samples: int = 1024) -> np.ndarray:
        """Half the peak-to-peak displacement of every DOF: the extrema sampled at `samples`
        points, then refined by a bounded scalar search around the best sample (to ~1e-15)."""
        T = self.period
        times = np.arange(samples) * T / samples
        x = self.displacement(times)
        out = np.zeros(self.flows.n)
        for j in range(self.flows.n):
            ext = []
            for sign in (1.0, -1.0):
                i = int(np.argmax(sign * x[:, j]))
                f = lambda t: -sign * self.state(t)[j]  # noqa: E731
                r = minimize_scalar(f, bounds=(times[i] - T / samples, times[i] + T / samples), method="bounded",
                                    options={"xatol": 1e-12 * T})
                ext.append(max(sign * x[i, j], -r.fun))
            out[j] = 0.5 * (ext[0] + ext[1])
        return out

    def stuck_fraction(self) -> float:
        T, stuck = self.period, 0.0
        for i, (start, phase, _) in enumerate(self.segments):
            end = self.segments[i + 1][0] if i + 1 < len(self.segments) else self.t0 + T
            if phase == STICK:
                stuck += end - start
        return stuck / T

    def events(self):
        return [(t % self.period, p) for t, p, _ in self.segments[1:]]


def solve(s: FrictionSystem, substeps: int = 400, march_tol: float = 1e-7, max_periods: int = 4000,
          tol: float = 1e-13) -> FrictionOrbit:
    fl = Flows(s)
    T = s.period
    fl.set_step(T / substeps)
    n = s.n
    y = np.zeros(fl.dim)
    y[fl.ic] = 1.0
    y[-1] = 1.0
    phase = fl.initial_phase(y)
    prev = y.copy()
    periods = 0
    for periods in range(1, max_periods + 1):
        y, phase, _ = _march(fl, 0.0, y, phase, T)
        y[fl.ic], y[fl.isn] = 1.0, 0.0
        scale = max(np.abs(y[: 2 * n]).max(), 1e-300)
        if np.abs(y[: 2 * n] - prev[: 2 * n]).max() <= march_tol * scale:
            break
        prev = y.copy()
    # One recorded period; the shooting section: the middle of its longest phase.
    _, _, segs = _march(fl, 0.0, y, phase, T, record=True)
    bounds = [sg[0] for sg in segs] + [T]
    i = int(np.argmax(np.diff(bounds)))
    t0 = 0.5 * (bounds[i] + bounds[i + 1])
    y0 = fl.flow(segs[i][1], segs[i][2], t0 - segs[i][0])
    p0 = segs[i][1]
    k = 2 * n + 1   # unknowns x, v, w

    def period_map(z):
        yy = y0.copy()
        yy[:k] = z
        end, p_end, _ = _march(fl, t0, yy, p0, T)
        return end[:k], p_end

    def residual(z):
        end, p_end = period_map(z)
        r = z - end
        if p0 != STICK or s.kt is None:
            r[2 * n] = z[2 * n] - y0[2 * n]   # the slider is no state of this phase: pin it
        return r

    z, info, ier, msg = fsolve(residual, y0[:k], xtol=tol, full_output=True)
    res = np.abs(residual(z)).max()
    scale = np.abs(z[:n]).max()
    if not res <= 1e-10 * max(scale, 1e-300):
        raise RuntimeError(f"shooting did not converge: residual {res:.2e} ({msg})")
    y0 = y0.copy()
    y0[:k] = z
    _, _, segs = _march(fl, t0, y0, p0, T, record=True)
    return FrictionOrbit(fl, segs, t0, periods, res / scale)
