"""Exact periodic references (src/formulation.md §6), independent of any marcher and of the Rust engine.

- `linear_response`: continuous steady state without contact, any number of DOFs and harmonics.
- `linear_discrete`: the same for a discretised period (bds1, bds2, cds, galerkin, fourier), from
  the schemes' symbols (src/formulation.md §2 and §6.1): what the engine must reproduce to round-off.
- `compliant_stop`: 1-DOF bilinear oscillator m x'' + c x' + k x + k_c max(0, x - g0) = F cos Ωt,
  closed-form flows in both phases, Newton (scipy `root`) on (t0, t1, v0).
- `rigid_stop_sticking`: 1-DOF, rigid stop x <= g0 with plastic impact and a sticking phase.
- `rigid_stop_impacting`: 1-DOF, rigid stop, plastic impact without sticking (F <= k g0).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.integrate import solve_ivp
from scipy.linalg import expm
from scipy.optimize import brentq, minimize_scalar, root

from .model import System

# ----------------------------------------------------------------------------- linear


def _harmonic_loads(sys_: System) -> dict[int, np.ndarray]:
    """Complex load vector per harmonic: f(t) = sum_h Re[F_h e^{i h ω t}]."""
    loads: dict[int, np.ndarray] = {}
    for f in sys_.forces:
        F = loads.setdefault(f.harmonic, np.zeros(sys_.n, dtype=complex))
        F[f.dof] += f.amplitude * np.exp(1j * f.phase)
    return loads


def linear_response(sys_: System, t):
    """Continuous contact-free steady state x, v, a (each (n, len(t)))."""
    t = np.atleast_1d(np.asarray(t, dtype=float))
    M, C, K, w = sys_.mass, sys_.damping, sys_.stiffness, sys_.omega
    x = np.zeros((sys_.n, t.size))
    v = np.zeros_like(x)
    a = np.zeros_like(x)
    for h, F in _harmonic_loads(sys_).items():
        s = 1j * h * w
        X = np.linalg.solve(K + s * C + s * s * M, F)
        e = np.exp(s * t)[None, :]
        x += np.real(X[:, None] * e)
        v += np.real(s * X[:, None] * e)
        a += np.real(s * s * X[:, None] * e)
    return x, v, a


def scheme_symbols(scheme: str, theta: float, h: float, p: int | None = None, k: int | None = None,
                   omega: float | None = None):
    """(σ1, σ2, w) of a scheme at θ (src/formulation.md §2), z = e^{-iθ}. Fourier needs the signed wavenumber p,
    k and ω instead."""
    z = np.exp(-1j * theta)
    if scheme == "bds1":
        s1 = (1 - z) / h
        return s1, s1 * s1, 1.0
    if scheme == "bds2":
        return (3 - 4 * z + z * z) / (2 * h), (2 - 5 * z + 4 * z**2 - z**3) / h**2, 1.0
    if scheme in ("cds", "galerkin"):
        s1 = (1 / z - z) / (2 * h)
        s2 = (1 / z - 2 + z) / h**2
        return s1, s2, (1.0 if scheme == "cds" else (2 + np.cos(theta)) / 3)
    if scheme == "fourier":
        if p is None or k is None or omega is None:
            raise ValueError("fourier symbols need p, k and omega")
        s1 = 0.0 if (k % 2 == 0 and abs(p) == k // 2) else 1j * p * omega
        return s1, -(p * omega) ** 2, 1.0
    raise ValueError(f"unknown scheme {scheme!r}")


def linear_discrete(sys_: System, scheme: str, steps: int):
    """Discrete contact-free periodic solution at t_j = j T/k (src/formulation.md §6.1): x, v, a (n, k), where
    v and a are the scheme's derivative symbols applied to x."""
    k = steps
    T = sys_.period
    hs = T / k
    j = np.arange(k)
    M, C, K = sys_.mass, sys_.damping, sys_.stiffness
    x = np.zeros((sys_.n, k))
    v = np.zeros_like(x)
    a = np.zeros_like(x)
    for hm, F in _harmonic_loads(sys_).items():
        theta = 2 * np.pi * hm / k
        idx = hm % k
        p = idx if idx <= k // 2 else idx - k
        s1, s2, w = scheme_symbols(scheme, theta, hs, p=p, k=k, omega=sys_.omega)
        X = w * np.linalg.solve(s2 * M + s1 * C + w * K, F)
        e = np.exp(1j * theta * j)[None, :]
        x += np.real(X[:, None] * e)
        v += np.real(s1 * X[:, None] * e)
        a += np.real(s2 * X[:, None] * e)
    return x, v, a


# ----------------------------------------------------------------------------- 1-DOF flows


@dataclass(frozen=True)
class LinearFlow:
    """m x'' + c x' + ke x = F cos(Ω t) + b, closed form: particular periodic solution plus the
    matrix exponential of the homogeneous part."""

    m: float
    c: float
    ke: float
    F: float
    Omega: float
    b: float = 0.0

    def particular(self, t):
        X = self.F / (self.ke - self.m * self.Omega**2 + 1j * self.c * self.Omega)
        e = np.exp(1j * self.Omega * np.asarray(t, dtype=float))
        return np.real(X * e) + self.b / self.ke, np.real(1j * self.Omega * X * e)

    @property
    def A(self):
        return np.array([[0.0, 1.0], [-self.ke / self.m, -self.c / self.m]])

    def __call__(self, t, ta, ya):
        """State (x, v) at time(s) t starting from ya = (x, v) at ta (vectorised over t: the
        homogeneous part uses the eigen-decomposition of the 2x2 system matrix, checked against
        scipy.linalg.expm in the tests)."""
        t = np.asarray(t, dtype=float)
        xp, vp = self.particular(ta)
        d0 = np.array([ya[0] - xp, ya[1] - vp], dtype=complex)
        ts = np.atleast_1d(t)
        lam, V = np.linalg.eig(self.A.astype(complex))
        if abs(lam[0] - lam[1]) < 1e-9 * max(1.0, abs(lam[0])):  # (near) critical damping
            out = np.stack([expm(self.A * (ti - ta)) @ d0.real for ti in ts], axis=1)
        else:
            cvec = np.linalg.solve(V, d0)
            out = np.real(V @ (cvec[:, None] * np.exp(np.outer(lam, ts - ta))))
        xq, vq = self.particular(ts)
        out = out + np.vstack([xq, vq])
        return out[:, 0] if t.ndim == 0 else out

    def expm_state(self, t, ta, ya):
        """Same as __call__ for one t, with scipy.linalg.expm (reference for the tests)."""
        xp, vp = self.particular(ta)
        y = expm(self.A * (t - ta)) @ np.array([ya[0] - xp, ya[1] - vp])
        xq, vq = self.particular(t)
        return y + np.array([xq, vq])


# ----------------------------------------------------------------------------- compliant stop


@dataclass
class CompliantStopOrbit:
    """Periodic orbit of the bilinear oscillator with one contact phase per period:
    x > g0 on (t0, t1) (contact), x < g0 on (t1, t0 + T) (free)."""

    m: float
    c: float
    k: float
    kc: float
    g0: float
    F: float
    Omega: float
    t0: float
    t1: float
    v0: float

    @property
    def T(self):
        return 2 * np.pi / self.Omega

    @property
    def contact_flow(self):
        return LinearFlow(self.m, self.c, self.k + self.kc, self.F, self.Omega, self.kc * self.g0)

    @property
    def free_flow(self):
        return LinearFlow(self.m, self.c, self.k, self.F, self.Omega, 0.0)

    def state(self, t):
        """(x, v) at arbitrary times t (array)."""
        t = np.atleast_1d(np.asarray(t, dtype=float))
        tau = self.t0 + np.mod(t - self.t0, self.T)  # in [t0, t0 + T)
        y1 = self.contact_flow(self.t1, self.t0, (self.g0, self.v0))
        out = np.empty((2, t.size))
        inc = tau < self.t1
        if inc.any():
            out[:, inc] = self.contact_flow(tau[inc], self.t0, (self.g0, self.v0))
        if (~inc).any():
            out[:, ~inc] = self.free_flow(tau[~inc], self.t1, y1)
        return out

    def force(self, t):
        x = self.state(t)[0]
        return self.kc * np.maximum(0.0, x - self.g0)

    def impulse(self):
        """∫ contact force over one period (quadrature of the closed-form x on the contact arc)."""
        from scipy.integrate import quad

        return quad(lambda s: self.kc * (self.contact_flow(s, self.t0, (self.g0, self.v0))[0] - self.g0),
                    self.t0, self.t1, epsabs=1e-13, epsrel=1e-13, limit=200)[0]

    def residual(self):
        return _compliant_residual(np.array([self.t0, self.t1, self.v0]), self.m, self.c, self.k,
                                   self.kc, self.g0, self.F, self.Omega)


def _compliant_residual(u, m, c, k, kc, g0, F, Omega):
    t0, t1, v0 = u
    T = 2 * np.pi / Omega
    fc = LinearFlow(m, c, k + kc, F, Omega, kc * g0)
    ff = LinearFlow(m, c, k, F, Omega, 0.0)
    y1 = fc(t1, t0, (g0, v0))
    y2 = ff(t0 + T, t1, y1)
    return np.array([y1[0] - g0, y2[0] - g0, y2[1] - v0])


def _seed_compliant(m, c, k, kc, g0, F, Omega, max_periods=2000):
    """Rough seed (t0, t1, v0) from a plain low-accuracy integration from rest (Newton does the
    rest)."""
    T = 2 * np.pi / Omega

    def rhs(t, y):
        return [y[1], (F * np.cos(Omega * t) - c * y[1] - k * y[0] - kc * max(0.0, y[0] - g0)) / m]

    y = np.zeros(2)
    scale = 1.0
    for p in range(max_periods):
        sol = solve_ivp(rhs, (p * T, (p + 1) * T), y, rtol=1e-7, atol=1e-9, max_step=T / 50,
                        dense_output=True)
        y_new = sol.y[:, -1]
        scale = max(scale, np.max(np.abs(y_new)))
        done = p > 5 and np.max(np.abs(y_new - y)) < 1e-4 * scale
        y = y_new
        if done:
            break
    sol = solve_ivp(rhs, ((p + 1) * T, (p + 3) * T), y, rtol=1e-7, atol=1e-9, max_step=T / 50,
                    dense_output=True)
    tt = np.linspace((p + 1) * T, (p + 3) * T, 8001)
    xx = sol.sol(tt)[0] - g0
    up = np.flatnonzero((xx[:-1] <= 0) & (xx[1:] > 0))
    if up.size == 0:
        raise RuntimeError("compliant seed: no contact found")
    i0 = up[0]
    down = np.flatnonzero((xx[i0:-1] > 0) & (xx[i0 + 1:] <= 0))
    i1 = i0 + down[0]
    t0, t1 = tt[i0], tt[i1]
    v0 = sol.sol(t0)[1]
    t0r = np.mod(t0, T)
    return np.array([t0r, t0r + (t1 - t0), v0])


def compliant_stop(m, c, k, kc, g0, F, Omega, guess=None) -> CompliantStopOrbit:
    """Solve for the orbit with one contact phase per period (src/formulation.md §6.2); t0 in [0, T)."""
    args = (m, c, k, kc, g0, F, Omega)
    u = np.asarray(guess, dtype=float) if guess is not None else _seed_compliant(*args)
    sol = root(_compliant_residual, u, args=args, method="hybr", options={"xtol": 1e-15})
    if not sol.success and np.max(np.abs(sol.fun)) > 1e-11:
        raise RuntimeError(f"compliant_stop Newton failed: {sol.message}")
    t0, t1, v0 = sol.x
    T = 2 * np.pi / Omega
    shift = np.floor(t0 / T) * T
    orb = CompliantStopOrbit(m, c, k, kc, g0, F, Omega, t0 - shift, t1 - shift, v0)
    # consistency: contact on (t0, t1), free on (t1, t0 + T)
    tc = np.linspace(orb.t0, orb.t1, 2002)[1:-1]
    tf = np.linspace(orb.t1, orb.t0 + T, 4002)[1:-1]
    if np.any(orb.state(tc)[0] <= g0) or np.any(orb.state(tf)[0] >= g0):
        raise RuntimeError("compliant_stop: orbit has more than one contact phase per period")
    return orb


# ----------------------------------------------------------------------------- rigid stop


@dataclass
class RigidStopSticking:
    """1-DOF rigid stop x <= g0, plastic impact, with a sticking phase per period:
    free flight from (g0, 0) at td (release, Ω td = arccos(k g0/F)) to the impact at th, then stuck
    on [th, td + T] with force F cos Ωt - k g0."""

    m: float
    c: float
    k: float
    F: float
    g0: float
    Omega: float
    td: float
    th: float
    v_impact: float  # velocity just before impact (> 0: approaching)

    @property
    def T(self):
        return 2 * np.pi / self.Omega

    @property
    def flow(self):
        return LinearFlow(self.m, self.c, self.k, self.F, self.Omega)

    def state(self, t):
        t = np.atleast_1d(np.asarray(t, dtype=float))
        tau = self.td + np.mod(t - self.td, self.T)  # [td, td + T)
        out = np.zeros((2, t.size))
        free = tau < self.th
        out[0, ~free] = self.g0
        if free.any():
            out[:, free] = self.flow(tau[free], self.td, (self.g0, 0.0))
        return out

    def force(self, t):
        """Smooth contact force (the impact impulse excluded)."""
        t = np.atleast_1d(np.asarray(t, dtype=float))
        tau = self.td + np.mod(t - self.td, self.T)
        f = self.F * np.cos(self.Omega * tau) - self.k * self.g0
        return np.where(tau >= self.th, np.maximum(f, 0.0), 0.0)

    @property
    def impact_impulse(self):
        return self.m * self.v_impact

    @property
    def stick_impulse(self):
        a, b = self.th, self.td + self.T
        W = self.Omega
        return self.F / W * (np.sin(W * b) - np.sin(W * a)) - self.k * self.g0 * (b - a)

    @property
    def impulse(self):
        return self.impact_impulse + self.stick_impulse

    def min_x(self):
        ts = np.linspace(self.td, self.th, 4001)
        xs = self.flow(ts, self.td, (self.g0, 0.0))[0]
        i = int(np.argmin(xs))
        r = minimize_scalar(lambda s: self.flow(s, self.td, (self.g0, 0.0))[0],
                            bounds=(ts[max(i - 1, 0)], ts[min(i + 1, ts.size - 1)]), method="bounded",
                            options={"xatol": 1e-13})
        return float(r.fun)


def _first_return(flow: LinearFlow, ta, ya, g0, tmax, skip):
    """First t in (ta + skip, tmax] where x(t) crosses g0 upward."""
    ts = np.linspace(ta + skip, tmax, 20001)
    xs = flow(ts, ta, ya)[0] - g0
    up = np.flatnonzero((xs[:-1] < 0) & (xs[1:] >= 0))
    if up.size == 0:
        return None
    i = up[0]
    return brentq(lambda s: flow(s, ta, ya)[0] - g0, ts[i], ts[i + 1], xtol=1e-15, rtol=1e-15)


def rigid_stop_sticking(m, c, k, F, g0, Omega) -> RigidStopSticking:
    """Notes §6.3, with sticking (0 < k g0 < F)."""
    if not 0 < k * g0 < F:
        raise ValueError("sticking orbit needs 0 < k g0 < F")
    T = 2 * np.pi / Omega
    td = np.arccos(k * g0 / F) / Omega
    flow = LinearFlow(m, c, k, F, Omega)
    th = _first_return(flow, td, (g0, 0.0), g0, td + 2 * T, skip=1e-3 * T)
    if th is None:
        raise RuntimeError("rigid_stop_sticking: no return to the stop within two periods")
    if not (2 * np.pi - Omega * td - 1e-12 <= Omega * th <= 2 * np.pi + Omega * td + 1e-12):
        raise RuntimeError(f"rigid_stop_sticking: impact at Ωt = {Omega * th:.6f} does not close the orbit "
                           f"(needs [{2 * np.pi - Omega * td:.6f}, {2 * np.pi + Omega * td:.6f}])")
    v = flow(th, td, (g0, 0.0))[1]
    return RigidStopSticking(m, c, k, F, g0, Omega, td, th, float(v))


@dataclass
class RigidStopImpacting:
    """1-DOF rigid stop, plastic impact at t0 (mod T) and no sticking: free flight from (g0, 0)."""

    m: float
    c: float
    k: float
    F: float
    g0: float
    Omega: float
    t0: float
    v_impact: float

    @property
    def T(self):
        return 2 * np.pi / self.Omega

    @property
    def flow(self):
        return LinearFlow(self.m, self.c, self.k, self.F, self.Omega)

    def state(self, t):
        t = np.atleast_1d(np.asarray(t, dtype=float))
        tau = self.t0 + np.mod(t - self.t0, self.T)
        return self.flow(tau, self.t0, (self.g0, 0.0))

    @property
    def impulse(self):
        return self.m * self.v_impact


def rigid_stop_impacting(m, c, k, F, g0, Omega) -> list[RigidStopImpacting]:
    """All orbits with one plastic impact per period and no sticking (F cos Ωt0 <= k g0)."""
    T = 2 * np.pi / Omega
    flow = LinearFlow(m, c, k, F, Omega)

    def R(t0):
        return flow(t0 + T, t0, (g0, 0.0))[0] - g0

    grid = np.linspace(0, T, 721)
    vals = np.array([R(t) for t in grid])
    out = []
    for i in range(grid.size - 1):
        if vals[i] == 0 or vals[i] * vals[i + 1] < 0:
            t0 = brentq(R, grid[i], grid[i + 1], xtol=1e-15, rtol=1e-15) if vals[i] != 0 else grid[i]
            if F * np.cos(Omega * t0) - k * g0 > 1e-12:  # would stick
                continue
            ts = np.linspace(t0, t0 + T, 4001)[1:-1]
            xs = flow(ts, t0, (g0, 0.0))[0]
            if np.all(xs < g0):
                v = flow(t0 + T, t0, (g0, 0.0))[1]
                if v > 0:
                    out.append(RigidStopImpacting(m, c, k, F, g0, Omega, float(t0), float(v)))
    return out
