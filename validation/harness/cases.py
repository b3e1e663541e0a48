"""The validation cases and cached marching runs.

Each case is a System (marching/model.py) plus the engine runs to compare: (scheme, pairing,
steps) for the CLI, one of them for the FMU. The continuous reference of a case is the event-driven
marcher (compliant.py or rigid.py; the exact linear formula for the linear case); the discrete
reference of a (scheme, pairing, steps) run is the marcher of the same discrete equations
(central_difference.py for cds, multistep.py for bds1/bds2/galerkin), when it can be marched.
"""
from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np

from marching.central_difference import march_cds
from marching.compliant import march_compliant
from marching.model import Contact, Force, MarchResult, Motion, System
from marching.multistep import march_multistep
from marching.rigid import march_rigid

# Sampling of the continuous marchers: 4096 points per period, so that every k in {128, ..., 4096}
# that is a power of two lands on marcher samples (no interpolation).
SAMPLES = 4096
# Periodicity tolerance of the continuous marchers (defect between consecutive periods); with the
# contraction per period rho of these cases the remaining distance to the orbit, defect*rho/(1-rho),
# stays below ~1e-8 relative (recorded as MarchResult.error_bound).
TOL_CONTINUOUS = 1e-9
# The discrete marchers are the tight references of the engine: 1e-11.
TOL_DISCRETE = 1e-11


@dataclass(frozen=True)
class Run:
    scheme: str
    pairing: str
    steps: int

    @property
    def label(self) -> str:
        return f"{self.scheme}/{self.pairing} k={self.steps}"


@dataclass(frozen=True)
class Case:
    name: str
    title: str
    system: System
    kind: str                    # "rigid" | "compliant" | "linear"
    runs: tuple[Run, ...]        # CLI runs
    fmu_run: Run                 # FMU run
    sticking: bool = True        # rigid cases: does the orbit have sticking phases (2nd order) ?

    @property
    def output_dofs(self) -> list[int]:
        return list(range(self.system.n))


def _chain(n: int) -> np.ndarray:
    """Fixed-free spring chain, unit springs."""
    K = 2 * np.eye(n) - np.eye(n, k=1) - np.eye(n, k=-1)
    K[-1, -1] = 1.0
    return K


CASES: dict[str, Case] = {}


def _add(case: Case) -> None:
    CASES[case.name] = case


# 1. src/formulation.md §6.3: m = 1, c = 0.1, k = 1, F = 1, g0 = 0.5, Ω = 1 -> min x = -1.869854, impulse 2.80804.
#    Rigid: cds and galerkin with forward pairing (2nd order with sticking), bds1 same (1st order).
_add(Case(
    "rigid_stick_1dof", "1-DOF rigid stop with sticking (src/formulation.md §6.3)",
    System.build([[1.0]], [[1.0]], 1.0, forces=[Force(0, 1.0)], contacts=[Contact(0, 0.5)], damping=[[0.1]]),
    "rigid",
    (Run("cds", "forward", 512), Run("galerkin", "forward", 512), Run("bds1", "same", 512)),
    Run("cds", "forward", 512)))

# 2. src/formulation.md §6.2: bilinear oscillator, t0/T = 0.9389205916, t1/T = 1.1343892296, v0 = 4.460827031.
#    Compliant: every scheme with the same-instant pairing.
_add(Case(
    "compliant_1dof", "1-DOF compliant stop (src/formulation.md §6.2)",
    System.build([[1.0]], [[1.0]], 1.3, forces=[Force(0, 1.0)], contacts=[Contact(0, 1.0, stiffness=10.0)],
                 damping=[[0.05]]),
    "compliant",
    (Run("cds", "same", 512), Run("galerkin", "same", 512), Run("bds2", "same", 512), Run("bds1", "same", 512),
     Run("fourier", "same", 512), Run("cds", "forward", 512)),
    Run("cds", "same", 512)))

# 3. 2-DOF chain, unequal masses, Rayleigh damping, compliant stop on the tip (one contact phase
#    per period, contact-closed frequency 6.6 rad/s against ω = 0.7).
_add(Case(
    "compliant_2dof", "2-DOF chain, compliant stop on the tip",
    System.build(np.diag([1.0, 0.5]), _chain(2), 0.7, forces=[Force(1, 0.3)],
                 contacts=[Contact(1, 1.0, stiffness=20.0)], rayleigh=(0.05, 0.05)),
    "compliant",
    (Run("cds", "same", 1024), Run("galerkin", "same", 1024), Run("bds2", "same", 1024), Run("fourier", "same", 1024)),
    Run("cds", "same", 1024)))

# 4. 3-DOF chain, two rigid stops on opposite sides (tip: x2 <= 1.0; middle: x1 >= -0.6), one impact
#    and one sticking phase per contact and period.
_add(Case(
    "rigid_3dof_two_contacts", "3-DOF chain, two rigid stops",
    System.build(np.eye(3), _chain(3), 0.5, forces=[Force(2, 0.3)],
                 contacts=[Contact(2, 1.0, direction=1), Contact(1, 0.6, direction=-1)], rayleigh=(0.05, 0.02)),
    "rigid",
    (Run("cds", "forward", 512), Run("galerkin", "forward", 512), Run("bds1", "same", 512)),
    Run("cds", "forward", 512)))

# 5. Moving obstacle: the 1-DOF compliant stop of case 2 with gap(t) = 1 + 0.2 cos(2ωt + 0.5).
_add(Case(
    "moving_obstacle", "1-DOF compliant stop, moving obstacle (2nd harmonic)",
    System.build([[1.0]], [[1.0]], 1.3, forces=[Force(0, 1.0)],
                 contacts=[Contact(0, 1.0, stiffness=10.0, motion=(Motion(0.2, 2, 0.5),))], damping=[[0.05]]),
    "compliant",
    (Run("cds", "same", 512), Run("bds2", "same", 512), Run("fourier", "same", 512)),
    Run("cds", "same", 512)))

# 6. Linear 2-DOF without contact, three force terms (harmonics 1 and 2 with phases, a static one).
_add(Case(
    "linear_2dof", "2-DOF linear, no contact (harmonics 0, 1, 2)",
    System.build(np.eye(2), np.array([[2.0, -1.0], [-1.0, 1.5]]), 0.8,
                 forces=[Force(0, 1.0, 1, 0.3), Force(1, 0.5, 2, -1.0), Force(1, 0.2, 0, 0.0)],
                 rayleigh=(0.1, 0.02)),
    "linear",
    (Run("cds", "same", 256), Run("galerkin", "same", 256), Run("bds2", "same", 256), Run("bds1", "same", 256),
     Run("fourier", "same", 64)),
    Run("cds", "same", 256)))


# ----------------------------------------------------------------------------- cached marching


@functools.lru_cache(maxsize=None)
def continuous(name: str) -> MarchResult:
    """The event-driven marcher of a case (compliant.py for compliant/linear, rigid.py for rigid)."""
    case = CASES[name]
    if case.kind == "rigid":
        return march_rigid(case.system, tol=TOL_CONTINUOUS, samples=SAMPLES)
    return march_compliant(case.system, tol=TOL_CONTINUOUS, samples=SAMPLES)


@functools.lru_cache(maxsize=None)
def discrete(name: str, scheme: str, pairing: str, steps: int) -> MarchResult | None:
    """The marcher of the engine's discrete equations for this run, or None if not marchable."""
    case = CASES[name]
    if scheme == "fourier":
        return None
    if scheme == "cds":
        return march_cds(case.system, steps, pairing=pairing, tol=TOL_DISCRETE)
    try:
        return march_multistep(case.system, scheme, steps, pairing=pairing, tol=TOL_DISCRETE)
    except ValueError:
        return None
