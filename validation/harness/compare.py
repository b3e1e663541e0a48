"""Error measures and tolerance formulas.

Errors are relative to the peak-to-peak amplitude of the reference, per DOF, worst DOF reported
(marching.model.relative_errors).

Tolerances against the continuous reference are C·(ω_max h)^p with h = T/k and ω_max the largest
undamped eigenfrequency of the structure with the compliant contacts closed (System.max_frequency).
Scaling h by ω_max rather than by the forcing ω is what makes one constant fit all cases: the
error is driven by the fastest resolved motion (the contact-closed mode of a stiff penalty, the
highest chain mode), e.g. the 2-DOF compliant case has ω_max/ω = 9.4.

The order p comes from the notes (§2, §3 "findings"), confirmed by calibrate.py on these cases:
  - linear:    bds1 1; bds2, cds, galerkin 2; fourier exact (round-off) when the forcing
               harmonics are resolved.
  - compliant (same-instant pairing): bds1 1; bds2, cds, galerkin 2; fourier ~2 (kink in the
               force); forward pairing makes the force lag one step: 1.
  - rigid:     cds and galerkin with forward pairing 2 when the orbit has sticking phases, 1 for
               pure impacts (impact instant between samples); bds1 (same) 1; bds2 and fourier do
               not converge to the plastic-impact orbit (no tolerance: not compared).

The constants C are 3x the largest err/(ω_max h)^p measured by calibrate.py over the cases of that
class and k = 128...1024 (the discrete marchers reproduce the engine's equations, so the engine
must show the same errors); the measured values are quoted next to each constant. fourier cannot
be marched: its constants are the bds2 ones (same order, largest constant of the second-order
schemes) and are PROVISIONAL until measured on the engine. A rigid case without sticking phases
(Case.sticking = False) drops cds/galerkin to order 1 with the same constants (none of the
engine cases is one; the marcher tests cover the impacting orbit).
"""
from __future__ import annotations

import numpy as np

from marching.model import MarchResult, relative_errors

# (class, scheme, pairing) -> constants C of C (ω_max h)^p for the displacement ("x"), velocity
# ("v", None: not asserted) and impulse per period ("impulse", relative to the reference impulse).
# Each is 3x the largest measured err/(ω_max h)^p of calibrate.py (k = 128..1024), quoted after #.
CONSTANTS = {
    # compliant, same-instant pairing (cases compliant_1dof, compliant_2dof, moving_obstacle)
    ("compliant", "bds1", "same"): {"x": 6.0, "v": 13.0, "impulse": 3.0},        # 1.85, 4.26, 0.93
    ("compliant", "bds2", "same"): {"x": 1.5, "v": 1.6, "impulse": 2.2},         # 0.471, 0.525, 0.715
    ("compliant", "cds", "same"): {"x": 0.2, "v": 0.3, "impulse": 0.25},         # 0.057, 0.092, 0.074
    ("compliant", "galerkin", "same"): {"x": 0.1, "v": 0.25, "impulse": 0.1},    # 0.027, 0.079, 0.030
    ("compliant", "fourier", "same"): {"x": 1.5, "v": 1.6, "impulse": 2.2},      # PROVISIONAL (= bds2)
    # compliant, forward pairing: first order (force lags one step)
    ("compliant", "cds", "forward"): {"x": 4.0, "v": 9.0, "impulse": 1.5},       # 1.335, 2.786, 0.500
    # rigid: the velocity jumps at impacts, pointwise velocity errors stay O(1): not asserted
    ("rigid", "cds", "forward"): {"x": 0.35, "v": None, "impulse": 0.3},         # 0.111, -, 0.092
    ("rigid", "galerkin", "forward"): {"x": 0.45, "v": None, "impulse": 0.25},   # 0.147, -, 0.082
    ("rigid", "bds1", "same"): {"x": 3.5, "v": None, "impulse": 3.6},            # 1.103, -, 1.202
    # linear (also compared with the exact discrete formula, to round-off)
    ("linear", "bds1", "same"): {"x": 5.0, "v": 7.0, "impulse": None},           # 1.619, 2.264
    ("linear", "bds2", "same"): {"x": 3.6, "v": 4.7, "impulse": None},           # 1.196, 1.550
    ("linear", "cds", "same"): {"x": 0.35, "v": 0.5, "impulse": None},           # 0.108, 0.156
    ("linear", "galerkin", "same"): {"x": 0.35, "v": 0.4, "impulse": None},      # 0.106, 0.120
}
# fourier on a linear case reproduces the continuous solution to round-off (src/formulation.md §6.1)
FOURIER_LINEAR_TOL = 1e-9


def order(case, scheme: str, pairing: str) -> int | None:
    if case.kind == "linear":
        return {"bds1": 1}.get(scheme, 2)
    if case.kind == "compliant":
        if pairing == "forward" or scheme == "bds1":
            return 1
        return 2
    # rigid
    if scheme in ("cds", "galerkin") and pairing == "forward":
        return 2 if case.sticking else 1
    if scheme == "bds1" and pairing == "same":
        return 1
    return None


def tolerance(case, scheme: str, pairing: str, steps: int, what: str = "x") -> float | None:
    """C (ω_max h)^p for this case class, scheme and quantity; None when not asserted."""
    if case.kind == "linear" and scheme == "fourier":
        return FOURIER_LINEAR_TOL
    C = CONSTANTS.get((case.kind, scheme, pairing), {}).get(what)
    p = order(case, scheme, pairing)
    if C is None or p is None:
        return None
    h = case.system.period / steps
    return C * (case.system.max_frequency() * h) ** p


def ref_on_grid(ref: MarchResult, t: np.ndarray):
    """Reference x, v at phase times t (shape (n, len(t))): exact samples when t falls on the
    reference grid, cubic Hermite interpolation from (x, v) otherwise."""
    T = ref.period
    N = ref.t.size
    s = np.mod(np.asarray(t, dtype=float), T) / (T / N)
    j = np.rint(s).astype(int)
    if np.all(np.abs(s - j) < 1e-6):
        j %= N
        return ref.x[:, j], ref.v[:, j]
    j0 = np.floor(s).astype(int) % N
    j1 = (j0 + 1) % N
    u = s - np.floor(s)
    dt = T / N
    h00 = 2 * u**3 - 3 * u**2 + 1
    h10 = u**3 - 2 * u**2 + u
    h01 = -2 * u**3 + 3 * u**2
    h11 = u**3 - u**2
    x = h00 * ref.x[:, j0] + h10 * dt * ref.v[:, j0] + h01 * ref.x[:, j1] + h11 * dt * ref.v[:, j1]
    v = (1 - u) * ref.v[:, j0] + u * ref.v[:, j1]
    return x, v


def errors(ref_x: np.ndarray, x: np.ndarray) -> tuple[float, float]:
    return relative_errors(ref_x, x)


def impulse_error(ref_impulse, impulse) -> float:
    ref_impulse = np.asarray(ref_impulse, dtype=float)
    impulse = np.asarray(impulse, dtype=float)
    if ref_impulse.size == 0:
        return 0.0
    return float(np.max(np.abs(impulse - ref_impulse) / np.maximum(np.abs(ref_impulse), 1e-300)))


def onset_phase(t: np.ndarray, force: np.ndarray, period: float) -> float | None:
    """Phase (t/T) of the first sample where a contact force becomes positive (cyclically)."""
    force = np.atleast_2d(force)
    best = None
    for f in force:
        on = np.flatnonzero((f > 0) & (np.roll(f, 1) <= 0))
        if on.size:
            ph = float(t[on[0]] / period)
            best = ph if best is None else min(best, ph)
    return best


def phase_distance(a: float, b: float) -> float:
    """Distance between two phases in [0, 1) on the circle."""
    d = abs(a - b) % 1.0
    return min(d, 1.0 - d)
