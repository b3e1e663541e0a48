"""The mechanical model shared by the marchers, the exact references and the scene writer.

    M x'' + C x' + K x = f(t) - B^T z(t)

Sign conventions (src/formulation.md §1, user-facing): contact i with direction s in {+1, -1} acts on DOF d and
enforces s*x[d] <= gap(t). Its clearance is gap(t) - s*x[d] >= 0, its force z >= 0 is compressive
and pushes DOF d by -s*z, so row i of B is s*e_d^T. A compliant (penalty) contact of stiffness k_c
carries z = k_c * max(0, s*x[d] - gap(t)); a rigid one satisfies Signorini's conditions.

gap(t) = gap + sum_h a_h cos(h*omega*t + phi_h); f[dof] += amplitude*cos(harmonic*omega*t + phase).

Nothing here is shared with the Rust engine: this is a plain re-statement of the scene contract.
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field
import numpy as np


@dataclass(frozen=True)
class Motion:
    """One cosine term amplitude*cos(harmonic*omega*t + phase) of an obstacle motion."""

    amplitude: float
    harmonic: int
    phase: float = 0.0


@dataclass(frozen=True)
class Force:
    """f[dof] += amplitude*cos(harmonic*omega*t + phase)."""

    dof: int
    amplitude: float
    harmonic: int = 1
    phase: float = 0.0


@dataclass(frozen=True)
class Contact:
    dof: int
    gap: float
    direction: int = 1
    stiffness: float | None = None  # None: rigid
    motion: tuple[Motion, ...] = ()

    @property
    def rigid(self) -> bool:
        return self.stiffness is None

    def gap_at(self, omega: float, t, deriv: int = 0):
        """gap(t) or its derivative of order 0, 1 or 2 (t scalar or array)."""
        t = np.asarray(t, dtype=float)
        out = np.full(t.shape, self.gap if deriv == 0 else 0.0)
        for mo in self.motion:
            w = mo.harmonic * omega
            arg = w * t + mo.phase
            if deriv == 0:
                out = out + mo.amplitude * np.cos(arg)
            elif deriv == 1:
                out = out - mo.amplitude * w * np.sin(arg)
            elif deriv == 2:
                out = out - mo.amplitude * w * w * np.cos(arg)
            else:
                raise ValueError("deriv must be 0, 1 or 2")
        return out if out.ndim else float(out)


@dataclass(frozen=True)
class System:
    """A structure under harmonic forcing with unilateral contacts.

    `damping_spec` only records how the damping was given, so that the scene writer can emit
    either `matrix = ...` or `rayleigh = [alpha, beta]`; `damping` is always the matrix C.
    """

    mass: np.ndarray
    stiffness: np.ndarray
    damping: np.ndarray
    omega: float
    forces: tuple[Force, ...] = ()
    contacts: tuple[Contact, ...] = ()
    damping_spec: tuple | None = None  # None | ("matrix",) | ("rayleigh", alpha, beta)

    # ---------------------------------------------------------------- construction
    @staticmethod
    def build(mass, stiffness, omega, forces=(), contacts=(), damping=None, rayleigh=None) -> "System":
        M = np.atleast_2d(np.asarray(mass, dtype=float))
        K = np.atleast_2d(np.asarray(stiffness, dtype=float))
        n = M.shape[0]
        if M.shape != (n, n) or K.shape != (n, n):
            raise ValueError("mass and stiffness must be n x n")
        if damping is not None and rayleigh is not None:
            raise ValueError("give damping or rayleigh, not both")
        if rayleigh is not None:
            a, b = rayleigh
            C = a * M + b * K
            spec = ("rayleigh", float(a), float(b))
        elif damping is not None:
            C = np.atleast_2d(np.asarray(damping, dtype=float))
            spec = ("matrix",)
        else:
            C = np.zeros_like(M)
            spec = None
        sys_ = System(M, K, C, float(omega), tuple(forces), tuple(contacts), spec)
        sys_.check()
        return sys_

    def check(self) -> None:
        n = self.n
        for f in self.forces:
            if not 0 <= f.dof < n:
                raise ValueError(f"force dof {f.dof} out of range")
        for c in self.contacts:
            if not 0 <= c.dof < n:
                raise ValueError(f"contact dof {c.dof} out of range")
            if c.direction not in (1, -1):
                raise ValueError("contact direction must be +1 or -1")
            if c.stiffness is not None and c.stiffness <= 0:
                raise ValueError("contact stiffness must be > 0")

    def replace(self, **kw) -> "System":
        return dataclasses.replace(self, **kw)

    def with_parameters(self, frequency=None, force_scale=1.0, gap_offset=0.0) -> "System":
        """The FMU's tunable parameters applied to this system (ω, force scale, gap shift)."""
        forces = tuple(dataclasses.replace(f, amplitude=f.amplitude * force_scale) for f in self.forces)
        contacts = tuple(dataclasses.replace(c, gap=c.gap + gap_offset) for c in self.contacts)
        return self.replace(omega=self.omega if frequency is None else float(frequency),
                            forces=forces, contacts=contacts)

    # ---------------------------------------------------------------- sizes
    @property
    def n(self) -> int:
        return self.mass.shape[0]

    @property
    def m(self) -> int:
        return len(self.contacts)

    @property
    def period(self) -> float:
        return 2.0 * np.pi / self.omega

    @property
    def B(self) -> np.ndarray:
        """m x n contact matrix, row i = s_i e_{d_i}^T."""
        B = np.zeros((self.m, self.n))
        for i, c in enumerate(self.contacts):
            B[i, c.dof] = c.direction
        return B

    @property
    def all_rigid(self) -> bool:
        return all(c.rigid for c in self.contacts)

    @property
    def all_compliant(self) -> bool:
        return all(not c.rigid for c in self.contacts)

    # ---------------------------------------------------------------- time functions
    def force(self, t):
        """f(t): shape (n,) for scalar t, (n, len(t)) for an array."""
        t = np.asarray(t, dtype=float)
        out = np.zeros((self.n,) + t.shape)
        for f in self.forces:
            out[f.dof] += f.amplitude * np.cos(f.harmonic * self.omega * t + f.phase)
        return out

    def gaps(self, t, deriv: int = 0):
        """gap_i(t) (or derivative): shape (m,) for scalar t, (m, len(t)) for an array."""
        t = np.asarray(t, dtype=float)
        if self.m == 0:
            return np.zeros((0,) + t.shape)
        return np.array([np.asarray(c.gap_at(self.omega, t, deriv)) for c in self.contacts])

    def clearance(self, t, x):
        """gap(t) - B x for x of shape (n,) or (n, N)."""
        return self.gaps(t) - self.B @ x

    def max_frequency(self) -> float:
        """Largest undamped eigenfrequency, compliant contacts closed (for explicit-scheme stability)."""
        K = self.stiffness.copy()
        for c in self.contacts:
            if not c.rigid:
                K[c.dof, c.dof] += c.stiffness
        lam = np.linalg.eigvals(np.linalg.solve(self.mass, K))
        return float(np.sqrt(np.max(np.abs(lam))))


@dataclass
class MarchResult:
    """What every marcher returns.

    `t` is the phase grid of the last period, t_j = j*T/N (N samples, endpoint excluded): the
    marchers start at t = 0 from rest and integrate whole periods, so phase 0 of the grid is phase
    0 of the forcing. x, v, a: (n, N). force: (m, N) contact forces (compliant: penalty force;
    rigid event-driven: the smooth force of sticking phases, impacts are in `impacts`; central
    differences: the multiplier z_j of step j, an impulse per step divided by h).
    impulse: (m,) impulse per period over the last period. impacts: [(phase time, contact, impulse)]
    of the last period (rigid event-driven only). onsets: [(phase time, contact)] times in the
    last period at which a contact closes (impact or start of penetration).
    """

    method: str
    system: System
    t: np.ndarray
    x: np.ndarray
    v: np.ndarray
    a: np.ndarray
    force: np.ndarray
    impulse: np.ndarray
    periods: int
    cpu_time: float
    defect: float
    defect_history: list[float]
    hist_t: np.ndarray
    hist_x: np.ndarray
    impacts: list = field(default_factory=list)
    onsets: list = field(default_factory=list)
    steps: int | None = None
    info: dict = field(default_factory=dict)

    @property
    def period(self) -> float:
        return self.system.period

    @property
    def contraction(self) -> float:
        """Per-period contraction ratio estimated from the last defects (nan if unknown)."""
        d = [v for v in self.defect_history[-6:] if v > 0]
        if len(d) < 3:
            return float("nan")
        r = np.exp(np.mean(np.diff(np.log(d))))
        return float(r)

    @property
    def error_bound(self) -> float:
        """Estimated distance of the last period to the periodic orbit, relative to the
        peak-to-peak amplitude: defect * rho/(1 - rho) for a geometric transient of ratio rho.
        The defect itself when too few periods were needed to estimate rho (finite-time
        convergence, e.g. through sticking)."""
        if self.defect == 0.0:
            return 0.0
        r = self.contraction
        if not np.isfinite(r):  # converged in a handful of periods (finite-time, through sticking)
            return self.defect
        if r >= 1.0:
            return float("inf")
        return self.defect * r / (1.0 - r)

    def first_onset_phase(self, contact: int | None = None) -> float | None:
        """Phase (time/T in [0,1)) of the first contact closure in the last period."""
        ts = [t for t, i in self.onsets if contact is None or i == contact]
        return min(ts) / self.period if ts else None


def periodicity_defect(x_prev: np.ndarray, x_cur: np.ndarray) -> float:
    """max |x_cur - x_prev| over the period and all DOFs, relative to the largest peak-to-peak
    amplitude of x_cur over the DOFs."""
    scale = float(np.max(np.ptp(x_cur, axis=1)))
    if scale == 0.0:
        scale = 1.0
    return float(np.max(np.abs(x_cur - x_prev))) / scale


def relative_errors(ref: np.ndarray, val: np.ndarray) -> tuple[float, float]:
    """(max, rms) of val - ref relative to the peak-to-peak amplitude of ref (per row; the worst
    row is reported)."""
    ref = np.atleast_2d(ref)
    val = np.atleast_2d(val)
    scale = np.ptp(ref, axis=1)
    scale[scale == 0] = 1.0
    d = (val - ref) / scale[:, None]
    return float(np.max(np.abs(d))), float(np.max(np.sqrt(np.mean(d * d, axis=1))))


def solve_lcp_murty(A: np.ndarray, q: np.ndarray, tol: float = 1e-13, max_iter: int = 100000):
    """Murty's least-index principal pivoting for w = A z + q (finite for P-matrices, e.g. the SPD
    step matrices of the marchers)."""
    m = len(q)
    eps = tol * max(1.0, float(np.max(np.abs(q))))
    basic = np.zeros(m, dtype=bool)
    for _ in range(max_iter):
        z = np.zeros(m)
        idx = np.flatnonzero(basic)
        if idx.size:
            z[idx] = np.linalg.solve(A[np.ix_(idx, idx)], -q[idx])
        w = A @ z + q
        bad = np.flatnonzero((basic & (z < -eps)) | (~basic & (w < -eps)))
        if bad.size == 0:
            return np.maximum(z, 0.0)
        basic[bad[0]] = ~basic[bad[0]]
    raise RuntimeError("LCP (Murty): no convergence")


def solve_lcp_enum(A: np.ndarray, q: np.ndarray, first_guess=None, tol: float = 1e-13):
    """w = A z + q, z >= 0, w >= 0, z.w = 0 for small m (<= 8) by enumerating active sets
    (Murty's principal pivoting beyond 8).

    Tries `first_guess` (a boolean mask) first, then all subsets by increasing size. Returns z.
    Raises if no complementary solution exists (within tol relative to |q|)."""
    m = len(q)
    if m == 0:
        return np.zeros(0)
    if m > 8:
        return solve_lcp_murty(A, q, tol=tol)
    scale = max(1.0, float(np.max(np.abs(q))))
    eps = tol * scale

    def attempt(mask):
        z = np.zeros(m)
        idx = np.flatnonzero(mask)
        if idx.size:
            try:
                z[idx] = np.linalg.solve(A[np.ix_(idx, idx)], -q[idx])
            except np.linalg.LinAlgError:
                return None
            if np.any(z[idx] < -eps):
                return None
        w = A @ z + q
        rest = ~mask
        if np.any(w[rest] < -eps):
            return None
        return np.maximum(z, 0.0)

    if first_guess is not None:
        z = attempt(np.asarray(first_guess, dtype=bool))
        if z is not None:
            return z
    for size in range(m + 1):
        for bits in range(1 << m):
            if bin(bits).count("1") != size:
                continue
            mask = np.array([(bits >> i) & 1 == 1 for i in range(m)])
            z = attempt(mask)
            if z is not None:
                return z
    raise RuntimeError("LCP by enumeration: no complementary solution")



def solve_contact_lcp(G: np.ndarray, cp: np.ndarray, tol: float = 1e-13) -> np.ndarray:
    """w = G z + cp, z >= 0, w >= 0, z.w = 0 for the contact LCP of a time step, any m: start from
    the predicted-active set {cp < 0}, solve the LCP restricted to the candidates (enumeration up
    to 8, principal pivoting beyond), add any other contact the correction pushes into the obstacle, repeat.
    Contacts outside the candidates keep z = 0 with w >= 0, so the result solves the full LCP."""
    m = cp.size
    z = np.zeros(m)
    cand = cp < 0
    if not cand.any():
        return z
    eps = tol * max(1.0, float(np.max(np.abs(cp))))
    while True:
        idx = np.flatnonzero(cand)
        zc = solve_lcp_enum(G[np.ix_(idx, idx)], cp[idx], first_guess=np.ones(idx.size, dtype=bool), tol=tol)
        w = cp + G[:, idx] @ zc
        viol = (w < -eps) & ~cand
        if not viol.any():
            z[idx] = zc
            return z
        cand |= viol


class PeriodMonitor:
    """Period-by-period bookkeeping shared by the marchers: the transient history kept for
    plots, and the stop test on the periodicity defect between consecutive periods."""

    def __init__(self, name: str, samples_per_period: int, history_per_period: int, tol: float,
                 min_periods: int, max_periods: int):
        self.name, self.tol = name, tol
        self.min_periods, self.max_periods = min_periods, max_periods
        self.stride = max(1, samples_per_period // history_per_period)
        self.hist_t: list = []
        self.hist_x: list = []
        self.defects: list[float] = []
        self.prev = None

    def end_period(self, p: int, t: np.ndarray, x: np.ndarray) -> bool:
        """Records period p (times t, samples x[dof, j]); True when the march may stop."""
        self.hist_t.append(t[::self.stride])
        self.hist_x.append(x[:, ::self.stride])
        if self.prev is not None:
            self.defects.append(periodicity_defect(self.prev, x))
        self.prev = x
        return p + 1 >= self.min_periods and bool(self.defects) and self.defects[-1] < self.tol

    def not_periodic(self) -> RuntimeError:
        return RuntimeError(f"{self.name} marcher: no periodicity within {self.max_periods} periods "
                            f"(last defect {self.defects[-1]:.3e})")

    def history(self) -> dict:
        """The MarchResult fields this monitor owns."""
        return dict(defect=self.defects[-1], defect_history=self.defects,
                    hist_t=np.concatenate(self.hist_t), hist_x=np.concatenate(self.hist_x, axis=1))
