"""Exact periodic orbits of a small linear structure with Coulomb friction contacts (rigid or
Jenkins, constant normal loads) AND compliant unilateral stops, by an event-driven simulation:
independent of the Rust crate (its LCP, its polish src/analysis/polish/friction/multi.rs and
multi/stops.rs). Extends friction_multi_exact.py (friction only):

    M x'' + C x' + K x = F cos(Ωt) − Σ_i b_i f_i − Σ_j c_j λ_j,   λ_j = k_j max(0, c_jᵀx − g_j)

- a mode is one phase per friction contact (stick, slip+, slip−) followed by one per stop (open,
  closed); a closed stop adds k_j c_j c_jᵀ to K and k_j g_j c_j to the load, before the stuck
  rigid contacts' saddle system, so the reactions see it;
- a stop's event is c_jᵀx = g_j (closing from open, opening from closed), found like the friction
  events (sign check on a grid, Brent on the closed-form flow); the state is continuous there.

Self-check (`python friction_contact_exact.py check`): a 2-DOF chain with one rigid Coulomb contact
and one stop against DOP853 on the regularised friction law f = μN tanh(v/ε) with the stop's
max(0, ·) integrated with event location (the difference must fall with ε); and with the stop
never reached (gap large) it equals friction_multi_exact.py.
"""
from __future__ import annotations

import sys

import numpy as np
from scipy.integrate import solve_ivp

try:
    from peers import friction_multi_exact as fx
except ImportError:  # run as a script from validation/peers
    import friction_multi_exact as fx

STICK, UP, DOWN = fx.STICK, fx.UP, fx.DOWN
OPEN, CLOSED = 2, 3


class ContactSystem(fx.System):
    def __init__(self, M, C, K, F, omega, contacts, stops):
        """contacts: (b, μN, k_t or None) per friction contact; stops: (c, gap, k_c) per stop."""
        super().__init__(M, C, K, F, omega, contacts)
        self.stops = [(np.asarray(c, float), float(g), float(k)) for c, g, k in stops]

    def rest_mode(self):
        return tuple([STICK] * self.m + [CLOSED if g < 0 else OPEN for _, g, _ in self.stops])

    def more_forces(self, mode, r):
        n = self.n
        for ph, (c, g, k) in zip(mode[self.m:], self.stops):
            if ph == CLOSED:
                r[:, :n] -= k * np.outer(c, c)
                r[:, self.i1] += k * g * c

    def penetration(self, j, y):
        c, g, _ = self.stops[j]
        return c @ y[:self.n] - g

    def g(self, mode, i, y):
        if i < self.m:
            return super().g(mode, i, y)
        p = self.penetration(i - self.m, y)
        return p if mode[i] == CLOSED else -p

    def switch(self, mode, i, y):
        if i < self.m:
            return super().switch(mode, i, y)
        new = list(mode)
        new[i] = OPEN if mode[i] == CLOSED else CLOSED
        return tuple(new), y


def regularised(s, orbit, eps, periods=40):
    """DOP853 on f = μN tanh(v/ε) (rigid friction contacts only) with the stops' kinks located as
    events, from the exact orbit's state at t = 0; returns max |x − x_exact| / max |x_exact|."""
    n = s.n
    Minv = np.linalg.inv(s.M)

    def rhs(t, z):
        x, v = z[:n], z[n:]
        f = sum(b * sl * np.tanh((b @ v) / eps) for b, sl in zip(s.b, s.slip))
        f = f + sum(c * k * max(0.0, c @ x - g) for c, g, k in s.stops)
        return np.concatenate([v, Minv @ (s.F * np.cos(s.omega * t) - s.K @ x - s.C @ v - f)])

    kinks = [lambda t, z, c=c, g=g: c @ z[:n] - g for c, g, _ in s.stops]
    y0 = orbit.at(0.0)[1][:2 * n]
    T = s.period
    ts = np.linspace((periods - 1) * T, periods * T, 97, endpoint=False)
    sol = solve_ivp(rhs, (0, periods * T), y0, method="DOP853", rtol=1e-11, atol=1e-13, t_eval=ts, events=kinks)
    exact = np.array([orbit.displacement(t) for t in ts]).T
    return np.max(np.abs(sol.y[:n] - exact)) / np.max(np.abs(exact))


def chain_stop(omega, slip=0.25, gap=0.4, kc=5.0, kt=None):
    """The 2-DOF chain of friction_multi_exact.chain: friction μN on m2, a stop on m1 at x1 ≤ gap."""
    M = np.diag([1.0, 0.5])
    C = np.array([[0.06, -0.02], [-0.02, 0.02]])
    K = np.array([[2.0, -1.0], [-1.0, 1.0]])
    return ContactSystem(M, C, K, [1.0, 0.0], omega, [([0.0, 1.0], slip, kt)], [([1.0, 0.0], gap, kc)])


def main():
    if len(sys.argv) > 1 and sys.argv[1] == "check":
        far = fx.steady(chain_stop(0.8, gap=50.0))
        plain = fx.steady(fx.System(np.diag([1.0, 0.5]), [[0.06, -0.02], [-0.02, 0.02]], [[2.0, -1.0], [-1.0, 1.0]], [1.0, 0.0], 0.8,
                                    [([0.0, 1.0], 0.25, None)]))
        T = far.s.period
        d = max(np.abs(far.displacement(j * T / 64) - plain.displacement(j * T / 64)).max() for j in range(64))
        print(f"stop never reached (gap 50) against friction_multi_exact.py: {d:.1e}")
        for omega in (0.8, 1.3):
            s = chain_stop(omega)
            o = fx.steady(s)
            print(f"chain_stop Ω = {omega}: {len(o.events)} events, residual {o.residual:.1e}, stuck {o.stuck_fraction(0):.4f}")
            for eps in (1e-2, 1e-3, 1e-4):
                print(f"  DOP853, f = μN tanh(v/ε), ε = {eps:.0e}: {regularised(s, o, eps):.2e}")
        return
    import json
    for name, s in {"chain_stop Ω = 0.8": chain_stop(0.8), "chain_stop Ω = 1.3, Jenkins k_t = 3": chain_stop(1.3, kt=3.0)}.items():
        o = fx.steady(s)
        T = s.period
        print(name, json.dumps({"events": len(o.events), "residual": o.residual, "kinds": [e[1] for e in o.events],
                                "stuck_fraction": o.stuck_fraction(0), "x": [list(o.displacement(j * T / 16)) for j in range(16)]}))


if __name__ == "__main__":
    main()
