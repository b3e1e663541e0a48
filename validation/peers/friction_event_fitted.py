"""Prototype (diagnostic) of an event-fitted friction law on the half-step pairing (src/formulation.md §9).

Scheme: cds for the structure, the friction sample f_j on (t_j, t_j+1) paired with the mean slip velocity
v̄_j = (u_j+1 − u_j)/h, the structure feeling (f_j−1 + f_j)/2 at t_j (the half-step pairing).
Law per step: the relay f ∈ μN Sgn(v̄) except in a window of steps around each slip end, where the law
v̄ = c + ε s (s = f/μN, clamped to [−1, 1]) holds: the mean velocity the scheme gives when the exact
force (a jump inside the step) is replaced by its step mean, for a velocity whose slopes are a0 ∓ g
(a0 the acceleration without friction at the event, g = μN (M⁻¹)_dd):
  reversal (|a0| > g):  v̄ = (h/2)(|a0| s − g sign a0)
  stop     (|a0| < g):  v̄ = (h/2)(g s − a0)
(derivation in src/formulation.md §9). Each law is a positive diagonal ε/μN added to the box LCP (PSD kept);
a0 comes from the previous solve's velocities (fixed-point iteration over the laws).
Solved here by shooting on the march (one scalar piecewise-linear equation per step), state (u_j−1, u_j, f_j−1).
"""
from __future__ import annotations
import sys
import numpy as np
sys.path.insert(0, __file__.rsplit("/", 1)[0])
import friction_exact as fe  # noqa: E402


def march_rigid(s: fe.FrictionSystem, k: int, state, laws):
    """One period of the half-step scheme from state = (u_{-1}, u_0, f_{-1}); laws: {j: (c, eps)}."""
    n, d, mu_n = s.n, s.dof, s.slip_force
    h = s.period / k
    lhs = s.M / h**2 + s.C / (2 * h)
    W = np.linalg.inv(lhs)
    beta = W[d, d] / (2 * h)   # v̄_j = v_pred − beta f_j
    um, u = state[:n].copy(), state[n:2 * n].copy()
    fm = state[2 * n]
    us, fs, vs = np.zeros((k, n)), np.zeros(k), np.zeros(k)
    for j in range(k):
        t = j * h
        rhs = s.F * np.cos(s.omega * t) - s.K @ u + s.M @ (2 * u - um) / h**2 + s.C @ um / (2 * h)
        rhs[d] -= 0.5 * fm
        up = W @ rhs
        v_pred = (up[d] - u[d]) / h
        c, eps = laws.get(j, (0.0, 0.0))
        # v̄ = v_pred − beta·μN·s and v̄ − c − eps·s ∈ relay of s.
        den = beta * mu_n + eps
        sj = np.clip((v_pred - c) / den, -1.0, 1.0)
        f = sj * mu_n
        up = up - W[:, d] * 0.5 * f
        us[j], fs[j], vs[j] = u, f, (up[d] - u[d]) / h
        um, u, fm = u, up, f
    return np.concatenate([um, u, [fm]]), us, fs, vs


def march_jenkins(s: fe.FrictionSystem, k: int, state, laws=None):
    """A Jenkins element with node forces: cds, the structure feeling f_j at t_j, and the slider's return
    mapping over (t_j−1, t_j): f_j = clamp(f_j−1 + k_t (u_j − u_j−1), ±μN) (backward Euler on the slider,
    explicit here because cds's u_j does not depend on f_j)."""
    n, d, mu_n, kt = s.n, s.dof, s.slip_force, s.kt
    h = s.period / k
    W = np.linalg.inv(s.M / h**2 + s.C / (2 * h))
    um, u = state[:n].copy(), state[n:2 * n].copy()
    fm = state[2 * n]
    us, fs, vs = np.zeros((k, n)), np.zeros(k), np.zeros(k)
    for j in range(k):
        t = j * h
        f = np.clip(fm + kt * (u[d] - um[d]), -mu_n, mu_n)
        rhs = s.F * np.cos(s.omega * t) - s.K @ u + s.M @ (2 * u - um) / h**2 + s.C @ um / (2 * h)
        rhs[d] -= f
        up = W @ rhs
        us[j], fs[j], vs[j] = u, f, (u[d] - um[d]) / h
        um, u, fm = u, up, f
    return np.concatenate([um, u, [fm]]), us, fs, vs


def periodic(s, k, laws, guess=None, iters=40):
    n = s.n
    dim = 2 * n + 1
    march = march_jenkins if s.kt is not None else march_rigid
    y = np.zeros(dim) if guess is None else guess.copy()
    if guess is None:
        # march a few hundred periods to get near
        for _ in range(200):
            y, *_ = march(s, k, y, laws)
    for it in range(iters):
        end, us, fs, vs = march(s, k, y, laws)
        r = end - y
        scale = max(np.abs(us).max(), 1e-300)
        if np.abs(r).max() < 1e-13 * scale:
            return y, us, fs, vs
        J = np.zeros((dim, dim))
        delta = 1e-7 * scale
        for i in range(dim):
            yy = y.copy()
            yy[i] += delta
            J[:, i] = (march(s, k, yy, laws)[0] - end) / delta
        step = np.linalg.lstsq(np.eye(dim) - J, r, rcond=None)[0]
        lam = 1.0
        r0 = np.abs(r).max()
        while lam > 1e-3:
            yt = y + lam * step
            if np.abs(march(s, k, yt, laws)[0] - yt).max() < r0:
                break
            lam /= 2
        y = y + lam * step
    end, us, fs, vs = march(s, k, y, laws)
    return y, us, fs, vs


def fitted_laws(s, k, fs, vs, window=1):
    """The event laws from one solution's samples: a0 from the slip side's slope before the event."""
    mu_n = s.slip_force
    h = s.period / k
    g = mu_n * np.linalg.inv(s.M)[s.dof, s.dof]
    sg = fs / mu_n
    tol = 1e-9
    phase = np.where(sg > 1 - tol, 1, np.where(sg < -1 + tol, -1, 0))
    laws = {}
    for j in range(k):
        # an event between the last slip step j and step j+1 (or inside j+1 when it is interior)
        p, q = phase[j], phase[(j + 1) % k]
        if p == 0 or q == p:
            continue
        # slope of v̄ before: a⁻ = a0 − g·p
        am = (vs[j % k] - vs[(j - 1) % k]) / h if phase[(j - 1) % k] == p else (vs[(j - 1) % k] - vs[(j - 2) % k]) / h
        a0 = am + g * p
        for i in range(j + 1 - window, j + 2 + window):
            ii = i % k
            if abs(a0) > g:
                laws[ii] = (-(h / 2) * g * np.sign(a0), (h / 2) * abs(a0))
            else:
                laws[ii] = (-(h / 2) * a0, (h / 2) * g)
    return laws


def solve(s, k, fitted=True, rounds=8, verbose=False):
    laws = {}
    y, us, fs, vs = periodic(s, k, laws)
    if not fitted or s.kt is not None:
        return us, fs, vs, 0
    for r in range(rounds):
        new = fitted_laws(s, k, fs, vs)
        same = set(new) == set(laws) and all(abs(new[j][0] - laws[j][0]) + abs(new[j][1] - laws[j][1]) < 1e-12 for j in new)
        laws = new
        y, us, fs, vs = periodic(s, k, laws, guess=y)
        if same:
            return us, fs, vs, r + 1
    return us, fs, vs, rounds


def system(c, omega, slip, kt=None, chain=False):
    if chain:
        M = np.eye(2)
        K = np.array([[2.0, -1.0], [-1.0, 1.0]])
        C = c * np.eye(2)
        F = np.array([0.0, 1.0]); dof = 1
        return fe.FrictionSystem(M, C, K, F, omega, dof, slip, kt)
    return fe.FrictionSystem(np.eye(1), c * np.eye(1), np.eye(1), np.array([1.0]), omega, 0, slip, kt)


if __name__ == "__main__":
    cases = [(0.0, 0.6, 0.3), (0.0, 1.7, 0.2)]
    for c, om, sl in cases:
        s = system(c, om, sl)
        orb = fe.solve(s, substeps=2000, march_tol=1e-11, max_periods=20000)
        A = orb.amplitude()[0]
        for fitted in (False, True):
            row = []
            for k in (256, 512, 1024):
                us, fs, vs, rounds = solve(s, k, fitted)
                t = np.arange(k) * s.period / k
                x = orb.displacement(t)[:, 0]
                err = np.abs(us[:, 0] - x).max() / A
                amp = 0.5 * (us[:, 0].max() - us[:, 0].min())
                row.append((k, err, (amp - A) / A, rounds))
            print(c, om, sl, "fitted" if fitted else "relay", " ".join(f"k={k}: max {e:.2e} amp {a:+.2e} ({r})" for k, e, a, r in row), flush=True)
