"""Exact piecewise-linear flow of NLvib's Example 03 (Krack & Gross 2019, Example 03).

    x'' + D x' + K x + e0 * kc * max(0, x0 - gap) = e1 * f cos(Ω t)

M = I, K = [[1, -1], [-1, 2]], D = 0.03 K, kc = 100, gap = 1, f = 0.1 (DOF indices 0-based).
State y = [x0, x1, v0, v1]. In each regime r (0 = free, 1 = contact) the field is affine,

    y' = A_r y + b_r + e cos(Ω t),   A_r = [[0, I], [-K_r, -D]],  K_1 = K + kc e0 e0^T,
    b_1 = [0, 0, kc*gap, 0],  e = [0, 0, 0, f],

and its flow is exact: y(t) = y_p(t) + exp(A_r (t - ta)) (y(ta) - y_p(ta)) with the particular
harmonic solution y_p(t) = c_r + Re(Y_r e^{iΩt}), c_r = -A_r^{-1} b_r, (iΩ - A_r) Y_r = e.
exp(A_r τ) = V e^{Λτ} V^{-1} (A_r has 4 distinct eigenvalues; checked against scipy's expm in
the test). Switches (x0 = gap crossings) are found by root-finding on the exact flow: the sign of
v0 = dx0/dt is sampled on a sub-grid (h·ω_max <= 1/4) to split the segment into pieces where x0 is
monotone, and each piece whose ends straddle the gap is solved by Brent to ~1e-15.

Sensitivities. The field is continuous across x0 = gap (the spring force is 0 there), so the
saltation matrix of a transversal switch, S = I + (f⁺ - f⁻) n^T / (n^T f⁻), is the identity: the
monodromy is the product of the regimes' exponentials in time order, and the sensitivity to Ω,
z = ∂y/∂Ω, is continuous through switches as well (its jump (f⁻ - f⁺) dt_s/dΩ is 0). Inside a
regime z solves z' = A_r z + ∂(e cos Ωt)/∂Ω, whose particular solution is ∂y_p/∂Ω =
Re((Y_r' + i t Y_r) e^{iΩt}) with Y_r' = -(iΩ - A_r)^{-1} i Y_r; so z is exact too. With
T = 2π/Ω, dΦ_T/dΩ = z(T) + y'(T) dT/dΩ.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy.optimize import brentq

K_LIN = np.array([[1.0, -1.0], [-1.0, 2.0]])
DAMP = 0.03 * K_LIN
KC = 100.0
GAP = 1.0
FORCE = 0.1
# Brent's tolerances on a switch/extremum time: absolute 1e-15 s and the smallest relative one.
_XTOL = 1e-15
_RTOL = 4 * np.finfo(float).eps


@dataclass
class Regime:
    """One affine regime y' = A y + b + e cos(Ω t) and its exact flow at a given Ω."""

    A: np.ndarray
    b: np.ndarray
    omega: float
    lam: np.ndarray = field(init=False)
    V: np.ndarray = field(init=False)
    Vinv: np.ndarray = field(init=False)
    c: np.ndarray = field(init=False)
    Y: np.ndarray = field(init=False)
    dY: np.ndarray = field(init=False)

    def __post_init__(self):
        self.lam, self.V = np.linalg.eig(self.A)
        self.Vinv = np.linalg.inv(self.V)
        e = np.array([0.0, 0.0, 0.0, FORCE])
        self.c = -np.linalg.solve(self.A, self.b)
        R = 1j * self.omega * np.eye(4) - self.A
        self.Y = np.linalg.solve(R, e.astype(complex))
        self.dY = -np.linalg.solve(R, 1j * self.Y)

    def particular(self, t):
        """y_p(t) (shape (4,) for scalar t, (4, N) for an array)."""
        t = np.asarray(t, dtype=float)
        return (self.c[:, None] + (self.Y[:, None] * np.exp(1j * self.omega * t.reshape(1, -1))).real).reshape((4,) + t.shape)

    def dparticular(self, t):
        """∂y_p/∂Ω at t (scalar)."""
        ph = np.exp(1j * self.omega * t)
        return ((self.dY + 1j * t * self.Y) * ph).real

    def expm(self, tau: float) -> np.ndarray:
        return ((self.V * np.exp(self.lam * tau)) @ self.Vinv).real

    def field(self, t: float, y: np.ndarray) -> np.ndarray:
        return self.A @ y + self.b + np.array([0.0, 0.0, 0.0, FORCE * np.cos(self.omega * t)])

    def flow(self, ta: float, ya: np.ndarray, taus) -> np.ndarray:
        """States at ta + taus (taus >= 0; scalar -> (4,), array -> (4, N)) from y(ta) = ya."""
        taus = np.asarray(taus, dtype=float)
        w = self.Vinv @ (ya - self.particular(ta))
        hom = (self.V @ (np.exp(np.outer(self.lam, taus.reshape(-1))) * w[:, None])).real
        return (self.particular(ta + taus.reshape(-1)) + hom).reshape((4,) + taus.shape)


def _root(fn, a: float, b: float) -> float:
    """Brent's root of fn in [a, b]; when rounding makes the end values agree in sign (a root within
    ~1e-16 of an end), the end with the smaller |fn|."""
    fa, fb = fn(a), fn(b)
    if fa == 0.0:
        return a
    if fb == 0.0 or fa * fb > 0:
        return a if abs(fa) < abs(fb) else b
    return brentq(fn, a, b, xtol=_XTOL, rtol=_RTOL)


def state_matrix(contact: bool) -> tuple[np.ndarray, np.ndarray]:
    Kr = K_LIN.copy()
    b = np.zeros(4)
    if contact:
        Kr[0, 0] += KC
        b[2] = KC * GAP
    A = np.block([[np.zeros((2, 2)), np.eye(2)], [-Kr, -DAMP]])
    return A, b


@dataclass
class Segment:
    """A piece of trajectory in one regime: y(t) for t in [t0, t1]."""

    contact: bool
    t0: float
    t1: float
    y0: np.ndarray


@dataclass
class FlowResult:
    y: np.ndarray                     # state at t_end
    segments: list[Segment]
    monodromy: np.ndarray | None = None   # ∂y(t_end)/∂y(t_start)
    domega: np.ndarray | None = None      # total d y(T(Ω))/dΩ for a period map (see period_map)


class Nlvib03:
    """Example 03 at one excitation frequency Ω."""

    def __init__(self, omega: float):
        self.omega = float(omega)
        self.T = 2 * np.pi / self.omega
        self.regimes = [Regime(*state_matrix(False), self.omega), Regime(*state_matrix(True), self.omega)]
        wmax = max(np.max(np.abs(r.lam.imag)) for r in self.regimes)
        # sub-grid for sign changes of v0: h·ω_max <= 1/4, so v0 cannot change sign twice in a cell
        self.h = 0.25 / max(wmax, self.omega)

    # ------------------------------------------------------------------ one segment
    def _first_switch(self, reg: Regime, contact: bool, ta: float, ya: np.ndarray, t_end: float):
        """Earliest t in (ta, t_end] where x0 crosses the gap leaving the regime, or None."""
        L = t_end - ta
        n = max(2, int(np.ceil(L / self.h)) + 1)
        taus = np.linspace(0.0, L, n)
        Y = reg.flow(ta, ya, taus)
        sgn = 1.0 if contact else -1.0
        g = sgn * (Y[0] - GAP)           # > 0 inside the regime
        gp = Y[2]
        g[0] = abs(g[0]) if abs(g[0]) < 1e-12 else g[0]   # just switched: count as inside

        def g_at(tau):
            if tau == 0.0:
                return g[0]
            return sgn * (reg.flow(ta, ya, tau)[0] - GAP)

        def v_at(tau):
            return reg.flow(ta, ya, tau)[2]

        for i in range(n - 1):
            a, b = taus[i], taus[i + 1]
            pieces = [(a, g[i], b, g[i + 1])]
            if gp[i] * gp[i + 1] < 0:       # an extremum of x0 inside: split at it
                te = _root(v_at, a, b)
                ge = g_at(te)
                pieces = [(a, g[i], te, ge), (te, ge, b, g[i + 1])]
            for pa, ga, pb, gb in pieces:
                if ga > 0 and gb <= 0:
                    tau = pb if gb == 0 else _root(g_at, pa, pb)
                    if tau > 0:             # never a zero-length segment
                        return ta + tau
        return None

    def integrate(self, t_start: float, y_start, t_end: float, sensitivities: bool = False) -> FlowResult:
        """Exact flow from (t_start, y_start) to t_end; with sensitivities, also the monodromy
        ∂y(t_end)/∂y(t_start) and z = ∂y(t_end)/∂Ω at fixed t_end."""
        y = np.asarray(y_start, dtype=float).copy()
        t = float(t_start)
        contact = bool(y[0] > GAP or (y[0] == GAP and y[2] > 0))
        segs: list[Segment] = []
        Mon = np.eye(4) if sensitivities else None
        z = np.zeros(4) if sensitivities else None
        while True:
            reg = self.regimes[int(contact)]
            ts = self._first_switch(reg, contact, t, y, t_end)
            t1 = t_end if ts is None else ts
            segs.append(Segment(contact, t, t1, y.copy()))
            y1 = reg.flow(t, y, t1 - t)
            if sensitivities:
                E = reg.expm(t1 - t)
                Mon = E @ Mon
                # z(t1) = ∂y_p(t1) + E (z(t) - ∂y_p(t)); identity saltation at the switch
                z = reg.dparticular(t1) + E @ (z - reg.dparticular(t))
            y, t = y1, t1
            if ts is None:
                break
            contact = not contact
            if ts >= t_end:
                break
        return FlowResult(y, segs, Mon, z)

    def period_map(self, s, sensitivities: bool = True) -> FlowResult:
        """Φ_T(s) over [0, T]; domega = dΦ_T/dΩ including the change of T = 2π/Ω."""
        res = self.integrate(0.0, s, self.T, sensitivities)
        if sensitivities:
            contact = res.segments[-1].contact
            fT = self.regimes[int(contact)].field(self.T, res.y)
            res.domega = res.domega + fT * (-2 * np.pi / self.omega ** 2)
        return res

    # ------------------------------------------------------------------ orbit measures
    def extrema(self, segs: list[Segment], comp: int):
        """(min, max) of state component comp over the segments (exact: derivative roots by Brent)."""
        lo, hi = np.inf, -np.inf
        for sg in segs:
            reg = self.regimes[int(sg.contact)]
            L = sg.t1 - sg.t0
            n = max(2, int(np.ceil(L / self.h)) + 1)
            taus = np.linspace(0.0, L, n)
            Y = reg.flow(sg.t0, sg.y0, taus)
            vals = list(Y[comp])
            d = Y[comp + 2]
            for i in np.flatnonzero(d[:-1] * d[1:] < 0):
                te = _root(lambda tau: reg.flow(sg.t0, sg.y0, tau)[comp + 2], taus[i], taus[i + 1])
                vals.append(reg.flow(sg.t0, sg.y0, te)[comp])
            lo, hi = min(lo, min(vals)), max(hi, max(vals))
        return lo, hi

    def orbit_measures(self, s, p: int = 1) -> dict:
        """Amplitudes (half peak-to-peak) of both DOFs, max x0, number of switches over p periods."""
        res = self.integrate(0.0, s, p * self.T)
        out = {}
        for i in range(2):
            lo, hi = self.extrema(res.segments, i)
            out[f"amplitude_{i}"] = 0.5 * (hi - lo)
            if i == 0:
                out["max_x0"] = hi
        out["switches"] = len(res.segments) - 1
        return out

    def sample(self, s, t_end: float, n: int):
        """States at n equally spaced times in [0, t_end] from y(0) = s (for plots and checks)."""
        res = self.integrate(0.0, s, t_end)
        ts = np.linspace(0.0, t_end, n)
        Y = np.empty((4, n))
        for sg in res.segments:
            m = (ts >= sg.t0) & (ts <= sg.t1)
            if m.any():
                Y[:, m] = self.regimes[int(sg.contact)].flow(sg.t0, sg.y0, ts[m] - sg.t0)
        return ts, Y
