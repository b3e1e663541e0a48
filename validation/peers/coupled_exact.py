"""Exact periodic orbits of coupled normal–tangential friction: a mass on a compliant plane
(src/formulation.md §9), by an event-driven simulation independent of the Rust crate.

    m_x x'' + (C v)_x + (K q)_x = f_x(t) − f          (x: tangential)
    m_y y'' + (C v)_y + (K q)_y = f_y(t) + λ          (y: normal, the plane at y = 0, y ≥ 0 free)
    λ = k_c·max(0, −y)   (compliant plane: no impacts, the force is continuous)
    f = μλ·sign(ẋ) in slip,  |f| ≤ μλ in stick (ẋ = 0),  f = 0 off the plane

K = [[k_x, k_xy], [k_xy, k_y]] couples the directions (an inclined spring), f(t) = F0 + Fc cos Ωt +
Fs sin Ωt per DOF (a pressing normal load N0 + N1 cos Ωt, a tangential drive). Four phases (FREE,
STICK, SLIP_UP, SLIP_DOWN), each linear with harmonic forcing: the state is augmented to
s = [x, y, ẋ, ẏ, cos Ωt, sin Ωt, 1] and each phase flows as s(t+τ) = e^{Aτ} s(t) (scipy's expm).
Events (contact onset y = 0↓, lift-off y = 0↑, slip end ẋ = 0, stick end |f_req| = μλ) are found
by a sign check on a grid of `substeps` per period and Brent's method on the closed-form flow. The
steady state: march from the static equilibrium until the period map repeats, then Newton
shooting (scipy's fsolve) on the 4 state components at t0 = 0 to `tol`.

Check (tests in validation/test_coupled_exact.py): k_xy = 0 with a constant normal load is Den
Hartog's oscillator with slip force μ·N0 (the plane's static λ = N0), and the periodic orbit of the
FREE phase alone (no plane reached) is the linear frequency response.

`python -m peers.coupled_exact` (from validation/) prints the samples at t = iT/16 and, with
`--cli`, the CLI's errors at k = 128…1024 on examples/friction/coupled.toml.
"""
from __future__ import annotations

import os
from dataclasses import dataclass, field

for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import numpy as np  # noqa: E402
from scipy.linalg import expm  # noqa: E402
from scipy.optimize import fsolve  # noqa: E402

try:  # the event-driven march is friction_exact's, on this file's flows
    from .friction_exact import _march  # noqa: E402
except ImportError:  # run as a script from validation/peers
    from friction_exact import _march  # noqa: E402

FREE, STICK, SLIP_UP, SLIP_DOWN = 0, 1, 2, 3
NAMES = ("free", "stick", "slip+", "slip-")
DIM, IC, IS, I1 = 7, 4, 5, 6


@dataclass
class CoupledSystem:
    mass: tuple = (1.0, 1.0)
    K: np.ndarray = field(default_factory=lambda: np.array([[1.0, 0.4], [0.4, 1.0]]))
    C: np.ndarray = field(default_factory=lambda: np.diag([0.1, 0.8]))
    plane: float = 10.0        # k_c of the compliant plane
    mu: float = 0.6
    F0: np.ndarray = field(default_factory=lambda: np.array([0.0, -1.0]))   # constant part (normal load −N0)
    Fc: np.ndarray = field(default_factory=lambda: np.array([0.0, -1.3]))   # cos Ωt amplitudes (−N1 on y)
    Fs: np.ndarray = field(default_factory=lambda: np.array([0.5, 0.0]))    # sin Ωt amplitudes (drive on x)
    omega: float = 1.5

    @property
    def period(self) -> float:
        return 2 * np.pi / self.omega


class Flows:
    """The phases' augmented matrices and event forms."""

    def __init__(self, s: CoupledSystem):
        self.s = s
        # r(s) = f(t) − K q − C v (2 rows), λ(s) = −k_c y in contact (a row).
        r = np.zeros((2, DIM))
        r[:, :2] = -s.K
        r[:, 2:4] = -s.C
        r[:, IC], r[:, IS], r[:, I1] = s.Fc, s.Fs, s.F0
        lam = np.zeros(DIM)
        lam[1] = -s.plane
        self.r, self.lam = r, lam
        mats = []
        for phase in (FREE, STICK, SLIP_UP, SLIP_DOWN):
            A = np.zeros((DIM, DIM))
            A[0, 2], A[1, 3] = 1.0, 1.0
            A[IC, IS], A[IS, IC] = -s.omega, s.omega
            rx, ry = r[0].copy(), r[1].copy()
            if phase != FREE:
                ry += lam
            if phase == SLIP_UP:
                rx -= s.mu * lam
            elif phase == SLIP_DOWN:
                rx += s.mu * lam
            if phase == STICK:
                A[0, 2] = 0.0   # ẋ = 0: x frozen, the friction force takes r_x
            else:
                A[2] = rx / s.mass[0]
            A[3] = ry / s.mass[1]
            mats.append(A)
        self.A = mats
        self.step_maps = None
        self.h = None

    def set_step(self, h: float):
        self.h = h
        self.step_maps = [expm(A * h) for A in self.A]

    def flow(self, phase: int, y: np.ndarray, tau: float) -> np.ndarray:
        return expm(self.A[phase] * tau) @ y

    def conditions(self, phase: int, y: np.ndarray) -> list[float]:
        """The phase's conditions, each > 0 while it lasts."""
        if phase == FREE:
            return [y[1]]
        if phase == STICK:
            return [-y[1], self.s.mu * (self.lam @ y) - abs(self.r[0] @ y)]
        sign = 1.0 if phase == SLIP_UP else -1.0
        return [-y[1], sign * y[2]]

    def event(self, phase: int, y: np.ndarray) -> float:
        return min(self.conditions(phase, y))

    def next_phase(self, phase: int, y: np.ndarray) -> int:
        """The phase after `phase` ends at y (a stuck velocity set to 0 in place)."""
        c = self.conditions(phase, y)
        ended = int(np.argmin(np.abs(c) / np.array([1.0] + [max(abs(v), 1.0) for v in c[1:]])))
        if phase == FREE:
            return self.contact_phase(y)
        if ended == 0:
            return FREE
        if phase == STICK:
            return SLIP_UP if self.r[0] @ y > 0 else SLIP_DOWN
        y[2] = 0.0
        return self.contact_phase(y)

    def contact_phase(self, y: np.ndarray) -> int:
        """The phase of a state on (or in) the plane: slip with ẋ's sign, at ẋ = 0 stick if
        |r_x| < μλ, else slip where r_x drives."""
        if y[2] > 0:
            return SLIP_UP
        if y[2] < 0:
            return SLIP_DOWN
        f = self.r[0] @ y
        if abs(f) < self.s.mu * (self.lam @ y):
            return STICK
        return SLIP_UP if f > 0 else SLIP_DOWN

    def initial_phase(self, y: np.ndarray) -> int:
        return FREE if y[1] > 0 else self.contact_phase(y)

    def friction(self, phase: int, y: np.ndarray) -> float:
        """f (acting on the structure as −f) in a phase."""
        if phase == FREE:
            return 0.0
        if phase == STICK:
            return self.r[0] @ y
        return (1.0 if phase == SLIP_UP else -1.0) * self.s.mu * (self.lam @ y)


@dataclass
class CoupledOrbit:
    flows: Flows
    segments: list
    periods_marched: int
    shooting_residual: float

    @property
    def period(self) -> float:
        return self.flows.s.period

    def at(self, t: float):
        """(state, phase) at time t (mod T)."""
        t = t % self.period
        starts = [sg[0] for sg in self.segments]
        i = max(0, int(np.searchsorted(starts, t, side="right")) - 1)
        start, phase, y = self.segments[i]
        return self.flows.flow(phase, y, t - start), phase

    def samples(self, times):
        """Rows [x, y, λ, f] at each time."""
        out = []
        for t in times:
            y, p = self.at(t)
            lam = 0.0 if p == FREE else self.flows.lam @ y
            out.append([y[0], y[1], lam, self.flows.friction(p, y)])
        return np.array(out)

    def events(self):
        return [(t, NAMES[p]) for t, p, _ in self.segments[1:]]


def solve(s: CoupledSystem, substeps: int = 800, march_tol: float = 1e-8, max_periods: int = 400,
          tol: float = 1e-13) -> CoupledOrbit:
    """The orbit reached from the static equilibrium under F0 on the plane (x with it, through
    the coupling), at rest."""
    Kc = s.K + np.diag([0.0, s.plane])
    return solve_from(s, np.linalg.solve(Kc, s.F0), np.zeros(2), substeps, march_tol, max_periods, tol)


def solve_from(s: CoupledSystem, q0, v0, substeps: int = 800, march_tol: float = 1e-8,
               max_periods: int = 400, tol: float = 1e-13) -> CoupledOrbit:
    """The orbit reached by marching from positions q0 and velocities v0 at t = 0, then shooting
    (a coupled system can hold several periodic orbits: each start reaches one)."""
    fl = Flows(s)
    T = s.period
    fl.set_step(T / substeps)
    y = np.zeros(DIM)
    y[IC], y[I1] = 1.0, 1.0
    y[:2], y[2:4] = q0, v0
    phase = fl.initial_phase(y)
    prev = y.copy()
    periods = 0
    for periods in range(1, max_periods + 1):
        y, phase, _ = _march(fl, 0.0, y, phase, T)
        y[IC], y[IS] = 1.0, 0.0
        scale = max(np.abs(y[:4]).max(), 1e-300)
        if np.abs(y[:4] - prev[:4]).max() <= march_tol * scale:
            break
        prev = y.copy()

    def residual(z):
        yy = y.copy()
        yy[:4] = z
        p0 = fl.initial_phase(yy)
        end, _, _ = _march(fl, 0.0, yy, p0, T)
        return z - end[:4]

    z, _, _, msg = fsolve(residual, y[:4], xtol=tol, full_output=True)
    res = np.abs(residual(z)).max()
    scale = np.abs(z).max()
    if not res <= 1e-10 * max(scale, 1e-300):
        raise RuntimeError(f"shooting did not converge: residual {res:.2e} ({msg})")
    y0 = y.copy()
    y0[:4] = z
    _, _, segs = _march(fl, 0.0, y0, fl.initial_phase(y0), T, record=True)
    return CoupledOrbit(fl, segs, periods, res / scale)


def wedging(s: CoupledSystem) -> float:
    """κ = μ·|G_nt|/G_nn from the static flexibilities (K⁻¹ plus the plane's 1/k_c on y)."""
    G = np.linalg.inv(s.K)
    return s.mu * abs(G[1, 0]) / (G[1, 1] + 1.0 / s.plane)


def example() -> CoupledSystem:
    """examples/friction/coupled.toml's system."""
    return CoupledSystem()


ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
SCENE = os.path.join(ROOT, "examples", "friction", "coupled.toml")
BINARY = os.path.join(ROOT, "target", "release", "periodic-contact")


def cli_errors(orbit: CoupledOrbit, scene: str = SCENE, steps=(128, 256, 512, 1024), binary: str = BINARY):
    """Max over the k instants of |x_k − x|, |y_k − y| (relative to max |x|, max |y|) and
    |λ_k − λ| (relative to max λ) for the CLI at each k."""
    import json
    import subprocess
    import tempfile
    out = []
    for k in steps:
        with tempfile.TemporaryDirectory() as d:
            path, toml = os.path.join(d, "r.json"), os.path.join(d, "scene.toml")
            with open(scene) as src, open(toml, "w") as dst:
                dst.write(src.read().replace("steps = 256", f"steps = {k}"))
            subprocess.run([binary, "solve", toml, "--no-estimate", "-o", path], check=True, capture_output=True)
            r = json.load(open(path))
        T = orbit.period
        ex = orbit.samples(np.arange(k) * T / k)
        x, yn = np.array(r["displacement"]["0"]), np.array(r["displacement"]["1"])
        lam = np.array(r["contacts"][0]["force"])
        e = []
        for every in (1, k // 16):
            pick = slice(0, k, every)
            e.append([np.abs(a[pick] - b[pick]).max() / np.abs(b[pick]).max() for a, b in ((x, ex[:, 0]), (yn, ex[:, 1]), (lam, ex[:, 2]))])
        out.append((k, e, r["lcp"]["pivots"], r["timing_s"]["total"]))
    return out


if __name__ == "__main__":
    import sys
    orbit = solve(example())
    print(f"marched {orbit.periods_marched} periods, shooting residual {orbit.shooting_residual:.1e}")
    for t, name in orbit.events():
        print(f"  event at t/T = {t / orbit.period:.10f} → {name}")
    print(f"κ = μ·|G_nt|/G_nn = {wedging(orbit.flows.s):.4f}")
    T = orbit.period
    s16 = orbit.samples(np.arange(16) * T / 16)
    print("x(iT/16) =", ", ".join(f"{v:.12e}" for v in s16[:, 0]))
    print("y(iT/16) =", ", ".join(f"{v:.12e}" for v in s16[:, 1]))
    print("λ(iT/16) =", ", ".join(f"{v:.12e}" for v in s16[:, 2]))
    print("f(iT/16) =", ", ".join(f"{v:.12e}" for v in s16[:, 3]))
    if "--cli" in sys.argv:
        steps = tuple(int(v) for v in sys.argv[sys.argv.index("--cli") + 1:]) or (128, 256, 512, 1024)
        for k, (e, e16), piv, t in cli_errors(orbit, steps=steps):
            print(f"k = {k:5}: errors at all instants x {e[0]:.4e}, y {e[1]:.4e}, λ {e[2]:.4e}; at t = iT/16 x {e16[0]:.4e}, y {e16[1]:.4e}, "
                  f"λ {e16[2]:.4e}; {piv} pivots, {t:.2f} s")
