"""Implicit time marching of the engine's *discrete* equations (src/formulation.md §2), one step at a time.

The periodic schemes are linear multistep stencils. Row j of the periodic system reads

    Σ_l (α_l M + β_l C + γ_l K) x_{j+l} + B^T z_j = Σ_l γ_l f_{j+l}

with the symbols σ2 = Σ α_l e^{ilθ}, σ1 = Σ β_l e^{ilθ}, w = Σ γ_l e^{ilθ} of the notes, and
force sample z_j complementary to the clearance at t_{j+π} (π = 0: pairing "same", π = 1:
"forward"). Marched forward in time from rest, each step solves for the newest sample x_{j+L}
(L = largest offset) with a small LCP when π = L, or with an explicit penalty force when π < L
(compliant contacts only). A k-periodic steady state of this recursion solves the engine's
periodic LCP for that scheme and pairing exactly, so it is a *discrete* reference, computed by a
different algorithm (marching instead of one LCP over the period), sharing no code with the
engine. `fourier` is global in time and cannot be marched.

Galerkin: the weight w = (2 + cos θ)/3 multiplies K and f (src/formulation.md §2); the contact force sample is
taken unweighted here (assumption, to be confirmed against the engine).
"""
from __future__ import annotations

import time

import numpy as np

from .model import MarchResult, System, PeriodMonitor, solve_contact_lcp


def stencils(scheme: str, h: float):
    """{offset: coefficient} for σ2 (α), σ1 (β) and w (γ)."""
    if scheme == "bds1":
        return {0: 1 / h**2, -1: -2 / h**2, -2: 1 / h**2}, {0: 1 / h, -1: -1 / h}, {0: 1.0}
    if scheme == "bds2":
        return ({0: 2 / h**2, -1: -5 / h**2, -2: 4 / h**2, -3: -1 / h**2},
                {0: 1.5 / h, -1: -2 / h, -2: 0.5 / h}, {0: 1.0})
    if scheme == "cds":
        return {1: 1 / h**2, 0: -2 / h**2, -1: 1 / h**2}, {1: 0.5 / h, -1: -0.5 / h}, {0: 1.0}
    if scheme == "galerkin":
        return ({1: 1 / h**2, 0: -2 / h**2, -1: 1 / h**2}, {1: 0.5 / h, -1: -0.5 / h},
                {-1: 1 / 6, 0: 4 / 6, 1: 1 / 6})
    raise ValueError(f"scheme {scheme!r} cannot be marched")


def march_multistep(sys_: System, scheme: str, steps: int, pairing: str = "same", tol: float = 1e-10,
                    min_periods: int = 3, max_periods: int = 20000, history_per_period: int = 64) -> MarchResult:
    cpu0 = time.process_time()
    n, m = sys_.n, sys_.m
    T = sys_.period
    k = int(steps)
    h = T / k
    al, be, ga = stencils(scheme, h)
    offs = sorted(set(al) | set(be) | set(ga))
    L, lo = offs[-1], offs[0]
    pi = {"same": 0, "forward": 1}[pairing]
    M, C, K = sys_.mass, sys_.damping, sys_.stiffness

    def coef(l):
        return al.get(l, 0.0) * M + be.get(l, 0.0) * C + ga.get(l, 0.0) * K

    Zl = {l: coef(l) for l in offs}
    W = np.linalg.inv(Zl[L])
    tj = np.arange(k) * h
    F = sys_.force(tj)  # (n, k)
    Fw = sum(g * np.roll(F, -l, axis=1) for l, g in ga.items())  # Σ γ_l f_{j+l}
    B = sys_.B
    rigid = np.array([c.rigid for c in sys_.contacts], dtype=bool)
    if pi > L:
        raise ValueError(f"{scheme} with pairing {pairing!r}: the force would precede its clearance; not marchable")
    implicit = np.full(m, pi == L)
    if np.any(rigid & ~implicit):
        raise ValueError(f"{scheme} with pairing {pairing!r} is ill-posed for rigid contacts")
    Ii, Ei = np.flatnonzero(implicit), np.flatnonzero(~implicit)
    BI, BE = B[Ii], B[Ei]
    WBI = W @ BI.T
    compl = np.array([0.0 if c.rigid else 1.0 / c.stiffness for c in sys_.contacts])
    GI = BI @ WBI + np.diag(compl[Ii])
    kE = np.array([sys_.contacts[i].stiffness for i in Ei], dtype=float)
    gaps = sys_.gaps(tj)
    # force sample j pairs with the clearance at j + pi
    gI = np.roll(gaps[Ii], -pi, axis=1).T.copy()
    gE = np.roll(gaps[Ei], -pi, axis=1).T.copy()
    WZ = {l: W @ Zl[l] for l in offs if l != L}
    WFw = (W @ Fw).T.copy()

    # ring buffer of the last L - lo samples x_{j+lo} ... x_{j+L-1}, from rest
    depth = L - lo
    buf = [np.zeros(n) for _ in range(depth)]  # buf[i] = x_{j+lo+i}
    monitor = PeriodMonitor(scheme, k, history_per_period, tol, min_periods, max_periods)
    lcp_calls = 0
    # Step j of period p computes x_{j+L}; it is stored in column (j+L) mod k, so for L = 1 column 0
    # holds the first sample of the next period (identical at the periodic steady state).
    for p in range(max_periods):
        X = np.empty((n, k))
        Z = np.zeros((m, k))
        for j in range(k):
            rhs = WFw[j].copy()
            for l, WZl in WZ.items():
                rhs -= WZl @ buf[l - lo]
            xn = rhs
            if Ei.size:  # explicit penalty at t_{j+pi}, pi < L: x_{j+pi} is known
                xk = buf[pi - lo]
                pen = BE @ xk - gE[j]
                if np.any(pen > 0):
                    ze = kE * np.maximum(pen, 0.0)
                    xn = xn - W @ (BE.T @ ze)
                    Z[Ei, j] = ze
            if Ii.size:
                cp = gI[j] - BI @ xn
                if np.any(cp < 0):
                    zi = solve_contact_lcp(GI, cp)
                    lcp_calls += 1
                    xn = xn - WBI @ zi
                    Z[Ii, j] = zi
            buf = buf[1:] + [xn]
            X[:, (j + L) % k] = xn
        if monitor.end_period(p, p * T + tj, X):
            break
    else:
        raise monitor.not_periodic()
    V = sum(b * np.roll(X, -l, axis=1) for l, b in be.items())
    A = sum(a * np.roll(X, -l, axis=1) for l, a in al.items())
    impulse = h * Z.sum(axis=1)
    onsets = []
    for i in range(m):
        on = np.flatnonzero((Z[i] > 0) & (np.roll(Z[i], 1) == 0))
        onsets += [(float(tj[j]), i) for j in on]
    onsets.sort()
    return MarchResult(
        method=f"{scheme}/{pairing}", system=sys_, t=tj, x=X, v=V, a=A, force=Z, impulse=impulse,
        periods=p + 1, cpu_time=time.process_time() - cpu0, **monitor.history(),
        onsets=onsets, steps=k,
        info={"lcp_calls": lcp_calls, "tol": tol})
