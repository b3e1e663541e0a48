"""Exact periodic orbits of a mass with Coulomb friction against a rigid stop (issue 25: "Den
Hartog's forced oscillator … with stops"), by an event-driven simulation independent of the Rust
crate:

    m x'' + c x' + k x = F cos Ωt − f − z,   f = μN·sign(v) in slip, |f| ≤ μN at rest,
    x ≤ g,  z ≥ 0,  z·(g − x) = 0,  plastic impacts (e = 0: v⁺ = 0).

Phases: slip up, slip down, rest (v = 0, x held). At rest the required holding force is
R = F cos Ωt − k x (what friction and the stop must supply against the spring and the load):
away from the stop the mass rests while |R| ≤ μN; on the stop (x = g) the stop takes any R ≥ 0
and friction holds R ∈ [−μN, 0), so it rests while R ≥ −μN, i.e. it departs at
Ω t_d = arccos((k g − μN)/F) (a closed form, checked by `check`). A slip ends at v = 0 (rest if
|R| ≤ μN, else a slip the way R points) or, upwards, at x = g (the impact stops the mass: rest on
the stop if R ≥ −μN, else it slips down at once). Between events every phase is linear with the
forcing carried as an oscillator, y = [x, v, cos Ωt, sin Ωt, 1], and flows by scipy's expm; the
events are found by a sign check on a grid and Brent's method on the closed-form flow.

    python friction_rigid_exact.py check      # the closed-form and cross checks
    PC_CLI=… python friction_rigid_exact.py lcp  # the CLI's plain LCP (bds1) against it
"""
from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
from dataclasses import dataclass

for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import numpy as np  # noqa: E402
from scipy.linalg import expm  # noqa: E402
from scipy.optimize import brentq  # noqa: E402

UP, DOWN, REST = 1, -1, 0


@dataclass
class RigidFriction:
    m: float
    c: float
    k: float
    F: float
    omega: float
    slip_force: float   # μN
    gap: float          # the stop: x ≤ gap

    @property
    def period(self) -> float:
        return 2 * np.pi / self.omega


class Flows:
    def __init__(self, s: RigidFriction):
        self.s = s
        w = s.omega
        rot = np.zeros((5, 5))
        rot[2, 3], rot[3, 2] = -w, w
        self.a = {REST: rot.copy()}
        for sign in (UP, DOWN):
            a = rot.copy()
            a[0, 1] = 1.0
            a[1] = [-s.k / s.m, -s.c / s.m, s.F / s.m, 0.0, -sign * s.slip_force / s.m]
            self.a[sign] = a
        self.step = {}

    def flow(self, phase: int, y: np.ndarray, tau: float) -> np.ndarray:
        return expm(self.a[phase] * tau) @ y

    def holding(self, y: np.ndarray) -> float:
        """R = F cos Ωt − k x: the force friction and the stop must supply at rest."""
        return self.s.F * y[2] - self.s.k * y[0]

    def on_stop(self, y: np.ndarray) -> bool:
        return y[0] >= self.s.gap - 1e-12 * max(1.0, abs(self.s.gap))

    def events(self, phase: int, y: np.ndarray) -> list[float]:
        """Event functions of `phase` at y: the phase ends where one turns negative."""
        s = self.s
        if phase == UP:
            return [y[1], s.gap - y[0]]
        if phase == DOWN:
            return [-y[1]]
        r = self.holding(y)
        lo = r + s.slip_force
        return [lo] if self.on_stop(y) else [lo, s.slip_force - r]

    def after(self, phase: int, y: np.ndarray) -> tuple[int, np.ndarray]:
        """The phase (and state) after `phase` ends at y."""
        s = self.s
        y = y.copy()
        if phase == UP and y[0] >= s.gap - 1e-13 * max(1.0, abs(s.gap)) and y[1] > 0:
            y[0], y[1] = s.gap, 0.0    # plastic impact
        if phase != REST:
            y[1] = 0.0
            r = self.holding(y)
            if self.on_stop(y):
                return (REST if r >= -s.slip_force else DOWN), y
            return (REST if abs(r) <= s.slip_force else (UP if r > 0 else DOWN)), y
        r = self.holding(y)
        return (UP if r > 0 and not self.on_stop(y) else DOWN), y


def march(fl: Flows, y: np.ndarray, phase: int, t0: float, duration: float, substeps: int, record=None):
    """Flows from (t0, y, phase) over `duration`; returns (y, phase); appends (t, phase, y) per event."""
    dt = fl.s.period / substeps
    t, end = t0, t0 + duration
    while t < end - 1e-15 * end:
        h = min(dt, end - t)
        yn = fl.flow(phase, y, h)
        ev = fl.events(phase, yn)
        hit = [i for i, e in enumerate(ev) if e < 0]
        if not hit:
            y, t = yn, t + h
            continue
        # The earliest event in (0, h]: Brent on each that turned negative.
        times = []
        for i in hit:
            g = lambda tau, i=i: fl.events(phase, fl.flow(phase, y, tau))[i]  # noqa: E731
            times.append(brentq(g, 0.0, h, xtol=1e-16, rtol=1e-15) if g(0.0) > 0 else 0.0)
        tau = min(times)
        ye = fl.flow(phase, y, tau)
        phase, y = fl.after(phase, ye)
        t += tau
        if record is not None:
            record.append((t, phase, y.copy()))
    return y, phase


@dataclass
class Orbit:
    fl: Flows
    t0: float
    y0: np.ndarray
    phase0: int
    events: list

    def state(self, t: float) -> np.ndarray:
        T = self.fl.s.period
        tt = self.t0 + (t - self.t0) % T
        y, ph, tp = self.y0, self.phase0, self.t0
        for (te, pe, ye) in self.events:
            if te > tt:
                break
            y, ph, tp = ye, pe, te
        return self.fl.flow(ph, y, tt - tp)

    def displacement(self, times) -> np.ndarray:
        return np.array([self.state(t)[0] for t in times])

    def amplitude(self, samples: int = 4096) -> float:
        x = self.displacement(np.arange(samples) * self.fl.s.period / samples)
        return 0.5 * (x.max() - x.min())

    def stuck_fraction(self) -> float:
        T = self.fl.s.period
        ends = [self.t0] + [e[0] for e in self.events] + [self.t0 + T]
        phases = [self.phase0] + [e[1] for e in self.events]
        return sum(b - a for a, b, p in zip(ends, ends[1:], phases) if p == REST) / T


def solve(s: RigidFriction, substeps: int = 400, tol: float = 1e-13, max_periods: int = 20000) -> Orbit:
    """Marches from rest at x = 0 until the state at the period boundaries repeats to `tol`."""
    fl = Flows(s)
    T = s.period
    y = np.array([0.0, 0.0, 1.0, 0.0, 1.0])
    phase = REST if abs(fl.holding(y)) <= s.slip_force else (UP if fl.holding(y) > 0 else DOWN)
    for p in range(max_periods):
        yn, phase = march(fl, y, phase, p * T, T, substeps)
        scale = max(1.0, np.abs(yn[:2]).max())
        if np.abs(yn[:2] - y[:2]).max() <= tol * scale:
            events: list = []
            y0, ph0 = yn.copy(), phase
            march(fl, yn, phase, 0.0, T, substeps, events)
            return Orbit(fl, 0.0, y0, ph0, events)
        y = yn
    raise RuntimeError(f"no periodic state in {max_periods} periods (last change {np.abs(yn[:2] - y[:2]).max():.2e})")


def departure_closed_form(s: RigidFriction) -> float | None:
    """Ω t_d = arccos((k g − μN)/F) in [0, π]: where the mass leaves the stop (R = −μN, falling)."""
    c = (s.k * s.gap - s.slip_force) / s.F
    return float(np.arccos(c)) / s.omega if -1 < c < 1 else None


def scene(s: RigidFriction, steps: int) -> str:
    fr = "" if s.slip_force == 0 else f"[[friction]]\ndof = 0\ncoefficient = 1.0\nnormal_force = {s.slip_force!r}\n"
    damping = f"[damping]\nmatrix = [[{s.c!r}]]\n" if s.c else ""
    return (f"[structure]\nmass = [[{s.m!r}]]\nstiffness = [[{s.k!r}]]\n{damping}[excitation]\nfrequency = {s.omega!r}\n"
            f"[[force]]\ndof = 0\namplitude = {s.F!r}\n[[contact]]\ndof = 0\ngap = {s.gap!r}\n{fr}"
            f"[discretization]\nscheme = \"bds1\"\nsteps = {steps}\n[output]\ndisplacement = [0]\ncontacts = true\n")


def cli_run(s: RigidFriction, steps: int, polish: bool = False) -> dict:
    cli = os.environ.get("PC_CLI", os.path.join(os.path.dirname(__file__), "..", "..", "target", "release", "periodic-contact"))
    with tempfile.TemporaryDirectory() as d:
        path, out = os.path.join(d, "s.toml"), os.path.join(d, "r.json")
        open(path, "w").write(scene(s, steps))
        args = [cli, "solve", path, "--no-estimate", "-o", out] + (["--polish"] if polish else [])
        p = subprocess.run(args, capture_output=True, text=True)
        if p.returncode != 0:
            raise RuntimeError(p.stderr)
        r = json.load(open(out))
        r["stderr"] = p.stderr
        return r


def error_at_instants(r: dict, o: Orbit) -> float:
    x = np.array(r["displacement"]["0"])
    return float(np.abs(x - o.displacement(np.array(r["time"]))).max() / o.amplitude())


# The cases: (name, system). Den Hartog's unit oscillator (m = k = F = 1) with a stop.
CASES = [
    ("c = 0, Ω = 0.8, μN = 0.3, stop at 0.5", RigidFriction(1.0, 0.0, 1.0, 1.0, 0.8, 0.3, 0.5)),
    ("c = 0.1, Ω = 1.438, μN = 0.2, stop at 0.3", RigidFriction(1.0, 0.1, 1.0, 1.0, 1.438, 0.2, 0.3)),
    ("c = 0.05, Ω = 1.438, μN = 0.5, stop at 0.1", RigidFriction(1.0, 0.05, 1.0, 1.0, 1.438, 0.5, 0.1)),
]


FRICTIONLESS = ("μN = 0, Ω = 0.8, stop at 0.5", RigidFriction(1.0, 0.0, 1.0, 1.0, 0.8, 0.0, 0.5))


def departure_errors() -> list[tuple[str, float]]:
    """|t_d − arccos((k g − μN)/F)/Ω| per case (μN = 0: the impact oscillator's, §6.3)."""
    rows = []
    for name, s in CASES + [FRICTIONLESS]:
        o = solve(s)
        td = departure_closed_form(s)
        before = [(o.t0, o.phase0, o.y0)] + o.events
        leaves = [t % s.period for (t, p, _), (_, p0, y0) in zip(o.events, before) if p0 == REST and p == DOWN and abs(y0[0] - s.gap) < 1e-12]
        err = min(abs(t - td) for t in leaves) if leaves and td is not None else float("nan")
        print(f"{name}: amplitude {o.amplitude():.12f}, stuck fraction {o.stuck_fraction():.9f}, {len(o.events)} events, "
              f"departure from the stop {leaves} against the closed form {td} (error {err:.2e})")
        rows.append((name, err))
    return rows


def out_of_reach_error() -> float:
    """A stop the orbit never reaches (gap 10): against friction_exact.py (Den Hartog with stops)."""
    try:
        from peers import friction_exact as fx
    except ImportError:  # run as a script from validation/peers
        import friction_exact as fx
    s = RigidFriction(1.0, 0.0, 1.0, 1.0, 1.438, 0.818, 10.0)
    o = solve(s)
    ref = fx.solve(fx.FrictionSystem(np.eye(1), np.zeros((1, 1)), np.eye(1), np.ones(1), 1.438, 0, 0.818))
    ts = np.linspace(0, s.period, 97, endpoint=False)
    d = float(np.abs(o.displacement(ts) - ref.displacement(ts)[:, 0]).max() / o.amplitude())
    print(f"stop out of reach (gap 10): against friction_exact.py {d:.2e} of the amplitude")
    return d


def check() -> None:
    departure_errors()
    out_of_reach_error()


def lcp_errors() -> list[tuple[str, float, float, float | None]]:
    """The CLI's plain LCP (bds1) at k = 256 and 512 against the simulation at the instants; for
    μN = 0 also the crate's rigid polish (src/analysis/polish/rigid.rs) at k = 256."""
    rows = []
    for name, s in CASES + [FRICTIONLESS]:
        o = solve(s)
        e256, e512 = (error_at_instants(cli_run(s, k), o) for k in (256, 512))
        polished = error_at_instants(cli_run(s, 256, polish=True), o) if s.slip_force == 0 else None
        print(f"{name}: plain LCP (bds1) error at the instants {e256:.3e} (k = 256), {e512:.3e} (k = 512), order {np.log2(e256 / e512):.2f}"
              + ("" if polished is None else f"; the crate's rigid polish (frictionless) at k = 256 {polished:.2e}"))
        rows.append((name, e256, e512, polished))
    return rows


def lcp() -> None:
    lcp_errors()


if __name__ == "__main__":
    {"check": check, "lcp": lcp}[sys.argv[1] if len(sys.argv) > 1 else "check"]()
