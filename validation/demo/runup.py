"""Drop-in demo: another component drives the PeriodicContact FMU through a slow frequency run-up.

Co-simulation (libcosimpy 0.0.6, libcosim's fixed-step master, FMI Library loader):

    FrequencyRamp.fmu  --frequency-->  frequency_in  PeriodicContact.fmu  --> displacement[0], ...
    (build_ramp.py)                                   (periodic-contact fmu SCENE.toml)

The driver is a separate FMI 2.0 CS FMU (a linear ramp f_start -> f_end over [t_start, t_end])
connected to our FMU's input `frequency_in` with `CosimExecution.connect_real_variables`. At each
macro step libcosim passes the driver's output at t_n to our FMU, which re-solves (warm-started)
for that frequency and outputs the periodic response at t_{n+1}. The frequency an output sample
was computed with is therefore the value of `frequency_in` observed at that sample (checked
against the ramp formula by the test).

The quasi-steady envelope is the sequence of local extrema of displacement[0] (maxima on the
stop side, minima on the free side); each is compared with `periodic-contact solve` of the same
scene at the frequency the FMU used for that sample (max x, resp. -min x). The linear curve is
the same scene without its contact, solved by the CLI. The coexisting contact orbit that the
engine does not return (above ~1.092 rad/s) is traced by time integration for the figure. See
README.md.

    cd validation && .venv/bin/python demo/runup.py            # writes figures/demo_runup.png

Environment: PC_CLI (the periodic-contact executable, default ../target/release/periodic-contact;
the FMU binary libPeriodicContact.so is taken next to it), PC_FMU_DIR (work folder, default a
temporary one), CC (C compiler for the driver FMU, default cc).
"""
from __future__ import annotations

import os
import sys
import tempfile
import time
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
VALIDATION = os.path.dirname(HERE)
for p in (VALIDATION, HERE):
    if p not in sys.path:
        sys.path.insert(0, p)

import build_ramp  # noqa: E402
from harness import engine  # noqa: E402
from harness.scene import scene_toml  # noqa: E402
from marching.model import Contact, Force, System  # noqa: E402

FIGURE = os.path.join(VALIDATION, "figures", "demo_runup.png")

# ----------------------------------------------------------------------------- the scene
# Damped oscillator (m = 1, k = 1, c = 0.05: linear resonance at 1 rad/s, peak 4.0 for F = 0.2)
# against a compliant stop (clearance 1, stiffness 10) on the positive side. The contact bends the
# resonance towards higher frequencies (hardening) and caps it at ~1.41; where the contact-free
# orbit fits in the clearance again (~1.09 rad/s) the engine's solution drops back to it.
MASS, STIFF, DAMP, FORCE = 1.0, 1.0, 0.05, 0.2
GAP, K_CONTACT = 1.0, 10.0
SCHEME, STEPS = "cds", 256

# ----------------------------------------------------------------------------- the run-up
W_START, W_END = 0.7, 1.4        # rad/s
T_RAMP = 900.0                   # s: ~150 excitation periods, Δω ≈ 0.005 rad/s per period
SAMPLES_PER_PERIOD = 64          # communication points per period at W_END


def system(omega: float, contact: bool = True) -> System:
    contacts = [Contact(0, GAP, stiffness=K_CONTACT)] if contact else []
    return System.build([[MASS]], [[STIFF]], omega, forces=[Force(0, FORCE)], contacts=contacts, damping=[[DAMP]])


def scene_text(omega: float, contact: bool = True) -> str:
    what = "against a compliant stop" if contact else "without its stop (linear reference)"
    return scene_toml(system(omega, contact), SCHEME, STEPS, displacement=[0], velocity=[0],
                      comment=f"drop-in demo: damped oscillator {what}")


# ----------------------------------------------------------------------------- FMUs


def build_fmus(cli: str, workdir: str) -> tuple[str, str]:
    """(PeriodicContact FMU of the scene at W_START, FrequencyRamp driver FMU)."""
    pc = engine.build_fmu(cli, scene_text(W_START), workdir, "demo_oscillator_stop")
    ramp = build_ramp.build(os.path.join(workdir, "FrequencyRamp.fmu"))
    return pc, ramp


@dataclass
class CosimRun:
    t: np.ndarray          # communication times [s], samples 0..n
    x: np.ndarray          # displacement[0]
    v: np.ndarray          # velocity[0]
    force: np.ndarray      # contact[0].force
    w_in: np.ndarray       # frequency_in of our FMU at each sample = the ω its output was computed with
    w_driver: np.ndarray   # the driver's output at each sample
    h: float               # communication step [s]
    wall_s: float
    extra: dict | None = None  # further Real outputs of our FMU asked by `extra`, by name


def _samples(obs, idx: int, vr: int, n: int) -> tuple[np.ndarray, np.ndarray]:
    # libcosimpy 0.0.6 trims the returned arrays by counting zero step numbers, which drops the
    # last retrieved sample when step 0 is among them: ask for two more than we need.
    times, steps, vals = obs.time_series_real_samples(idx, value_reference=vr, from_step=0, sample_count=n + 2)
    steps = np.asarray(steps)
    if steps.size < n or not np.array_equal(steps[:n], np.arange(n)):
        raise RuntimeError(f"libcosim observer returned steps {steps[:5]}... ({steps.size}), expected 0..{n - 1}")
    return np.asarray(times[:n], dtype=float) * 1e-9, np.asarray(vals[:n], dtype=float)


def cosimulate(pc_fmu: str, ramp_fmu: str, w_start: float = W_START, w_end: float = W_END, t_ramp: float = T_RAMP,
               samples_per_period: int = SAMPLES_PER_PERIOD, extra: tuple = ()) -> CosimRun:
    """Runs driver + PeriodicContact in libcosim over [0, t_ramp] (the ramp spans all of it);
    `extra`: names of further Real outputs of our FMU to observe."""
    from libcosimpy.CosimEnums import CosimVariableType
    from libcosimpy.CosimExecution import CosimExecution
    from libcosimpy.CosimLogging import CosimLogLevel, log_output_level
    from libcosimpy.CosimObserver import CosimObserver
    from libcosimpy.CosimSlave import CosimLocalSlave

    log_output_level(CosimLogLevel.WARNING)
    h_ns = int(round(2 * np.pi / max(w_start, w_end) / samples_per_period * 1e9))  # libcosim time: integer ns
    n_steps = int(round(t_ramp * 1e9)) // h_ns
    t0 = time.perf_counter()
    ex = CosimExecution.from_step_size(step_size=h_ns)
    i_r = ex.add_local_slave(local_slave=CosimLocalSlave(fmu_path=os.path.abspath(ramp_fmu), instance_name="ramp"))
    i_p = ex.add_local_slave(local_slave=CosimLocalSlave(fmu_path=os.path.abspath(pc_fmu), instance_name="contact"))

    def refs(i):
        return {v.name.decode(): v.reference for v in ex.slave_variables(i)}

    vr_r, vr_p = refs(i_r), refs(i_p)
    for name in ("frequency_in", "displacement[0]", "velocity[0]", "contact[0].force"):
        if name not in vr_p:
            raise RuntimeError(f"PeriodicContact FMU has no {name!r}; it has {sorted(vr_p)}")
    for name, val in (("f_start", w_start), ("f_end", w_end), ("t_start", 0.0), ("t_end", t_ramp)):
        if not ex.real_initial_value(i_r, vr_r[name], val):
            raise RuntimeError(f"libcosim refused the initial value of ramp.{name}")
    # Our FMU starts at the ramp's first value (its frequency_in is 0 = not driven until connected).
    if not ex.real_initial_value(i_p, vr_p["frequency"], w_start):
        raise RuntimeError("libcosim refused the initial value of contact.frequency")
    rc = ex.connect_real_variables(i_r, vr_r["frequency"], i_p, vr_p["frequency_in"])
    if rc not in (0, True):  # the C status (0 = success) is passed through
        raise RuntimeError(f"connect_real_variables failed ({rc})")

    obs = CosimObserver.create_time_series(buffer_size=n_steps + 10)
    ex.add_observer(observer=obs)
    series = [(i_p, "displacement[0]"), (i_p, "velocity[0]"), (i_p, "contact[0].force"), (i_p, "frequency_in"), (i_r, "frequency")]
    series += [(i_p, name) for name in extra]
    for i, name in series:
        vr = (vr_p if i == i_p else vr_r)[name]
        obs.start_time_series(i, value_reference=vr, variable_type=CosimVariableType.REAL)
    # one step more than needed: samples 0..n_steps are then all in the buffer
    if not ex.simulate_until(target_time=(n_steps + 1) * h_ns):
        raise RuntimeError("libcosim simulate_until failed (see the log above)")
    wall = time.perf_counter() - t0
    n = n_steps + 1
    out = {}
    t = None
    for i, name in series:
        vr = (vr_p if i == i_p else vr_r)[name]
        tt, vals = _samples(obs, i, vr, n)
        out[(i, name)] = vals
        t = tt
    return CosimRun(t=t, x=out[(i_p, "displacement[0]")], v=out[(i_p, "velocity[0]")], force=out[(i_p, "contact[0].force")],
                    w_in=out[(i_p, "frequency_in")], w_driver=out[(i_r, "frequency")], h=h_ns * 1e-9, wall_s=wall,
                    extra={name: out[(i_p, name)] for name in extra})


# ----------------------------------------------------------------------------- envelope


@dataclass
class Peaks:
    """The envelope of the FMU output: every local extremum of the sampled displacement."""
    idx: np.ndarray        # sample index
    t: np.ndarray
    omega: np.ndarray      # ω the FMU computed that sample with
    value: np.ndarray      # x at the extremum (upper: max x > 0 side, lower: min x, reported as -x)
    upper: np.ndarray      # True: local maximum of x (contact side), False: local minimum (free side)
    at_jump: np.ndarray    # the extremum touches a discontinuity of the output (not a peak of an orbit)


def jumps(run: CosimRun, rel: float = 1e-2) -> np.ndarray:
    """Steps n -> n+1 across which the output is discontinuous: the FMU switched to another
    periodic orbit at a re-solve. Continuity test with the FMU's own velocity output:
    |x_{n+1} - x_n - h (v_n + v_{n+1})/2| (trapezoid defect, O(h^3) for a smooth output, about
    1e-4 here) larger than rel * max|x|."""
    x, v, h = run.x, run.v, run.h
    defect = np.abs(x[1:] - x[:-1] - 0.5 * h * (v[1:] + v[:-1]))
    return np.nonzero(defect > rel * np.max(np.abs(x)))[0]


def peaks(run: CosimRun) -> Peaks:
    """Local maxima and minima of displacement[0] over the samples (sample 0, from the
    initialisation, and the last sample are excluded); for minima `value` is -x."""
    x = run.x
    mid = slice(1, -1)
    is_max = (x[mid] > x[:-2]) & (x[mid] >= x[2:])
    is_min = (x[mid] < x[:-2]) & (x[mid] <= x[2:])
    idx = np.nonzero(is_max | is_min)[0] + 1
    idx = idx[idx > 1]
    upper = is_max[idx - 1]
    val = np.where(upper, x[idx], -x[idx])
    j = jumps(run)
    at_jump = np.isin(idx, j) | np.isin(idx - 1, j)
    return Peaks(idx=idx, t=run.t[idx], omega=run.w_in[idx], value=val, upper=upper, at_jump=at_jump)


# ----------------------------------------------------------------------------- CLI sweep


@dataclass
class Sweep:
    omega: np.ndarray
    xmax: np.ndarray       # max_j x_j over the k instants (contact side)
    xmin: np.ndarray       # -min_j x_j (free side)
    acc: np.ndarray        # max_j |x_{j+1} - 2 x_j + x_{j-1}| / h^2 (for the sampling tolerance)
    pivots: np.ndarray

    @property
    def amp(self) -> np.ndarray:
        return np.maximum(self.xmax, self.xmin)

    def side(self, upper: np.ndarray) -> np.ndarray:
        return np.where(upper, self.xmax, self.xmin)


def cli_sweep(cli: str, omegas, workdir: str, contact: bool = True, jobs: int = 2) -> Sweep:
    """`periodic-contact solve` of the demo scene at each frequency (one process each)."""
    d = os.path.join(workdir, "sweep_contact" if contact else "sweep_linear")
    os.makedirs(d, exist_ok=True)

    def one(item):
        i, w = item
        r = engine.solve(cli, scene_text(float(w), contact), d, f"w{i:04d}")
        if r.problems:
            raise engine.EngineError(f"result at ω = {w}: {r.problems}")
        x = r.x[0]
        acc = (np.roll(x, -1) - 2 * x + np.roll(x, 1)) / (r.period / r.steps) ** 2  # periodic 2nd difference
        return (float(np.max(x)), float(-np.min(x)), float(np.max(np.abs(acc))), int(r.lcp.get("pivots", 0)))

    with ThreadPoolExecutor(max_workers=jobs) as pool:
        res = list(pool.map(one, enumerate(omegas)))
    a = np.array(res).reshape(-1, 4)
    return Sweep(np.asarray(omegas, dtype=float), a[:, 0], a[:, 1], a[:, 2], a[:, 3].astype(int))


# ----------------------------------------------------------------------------- agreement


def agreement(p: Peaks, cli: Sweep, run: CosimRun) -> dict:
    """Per extremum j of the FMU output: d = (FMU peak - CLI peak of the same side at ω_j) / CLI peak.

    Extrema next to a discontinuity of the output (`jumps`) are not compared.
    The FMU sample is a value of the very periodic response the CLI computes at ω_j (same engine,
    same scheme), so it cannot exceed the CLI peak by more than the interpolant's overshoot over
    the CLI's own samples, and it falls short by at most the sampling miss:
      sampling  ½ max|a| ((h/2)² + (h_cli/2)²), h the communication step, h_cli = T/k;
      drift     the samples around the peak were computed with ω_j ± one step of the ramp:
                |dA/dω| Δω_step (slope from the CLI values at the neighbouring extrema of the same
                side), which is large only at the jump of the response.
    """
    A = cli.side(p.upper)
    h_cli = 2 * np.pi / cli.omega / STEPS
    sampling = 0.5 * cli.acc * ((run.h / 2) ** 2 + (h_cli / 2) ** 2)
    dw = float(np.max(np.abs(np.diff(run.w_in[1:])))) if run.w_in.size > 2 else 0.0
    slope = np.zeros_like(A)
    for side in (True, False):
        m = np.nonzero(p.upper == side)[0]
        if m.size >= 3:
            g = np.abs(np.diff(A[m]) / np.maximum(np.diff(p.omega[m]), 1e-300))
            # the larger one-sided slope at each extremum
            slope[m] = np.maximum(np.concatenate([[g[0]], g]), np.concatenate([g, [g[-1]]]))
    drift = slope * dw
    tol = sampling + drift + 1e-9 * A
    d = (p.value - A) / A
    # An extremum next to a discontinuity of the output (the FMU switched orbit at that re-solve)
    # is not the peak of any periodic response: it is reported, not compared.
    return dict(d=d, tol_rel=tol / A, sampling_rel=sampling / A, drift_rel=drift / A,
                ok=(np.abs(p.value - A) <= tol) | p.at_jump, compared=~p.at_jump, dw_step=dw)


# ----------------------------------------------------------------------------- the other orbit

# Above ~1.092 rad/s the contact-free orbit fits in the clearance again and the engine returns it
# (cold CLI solve and warm-started FMU alike). The continuous system keeps a second, stable orbit
# with contact there (hardening): a physical slow run-up would stay on it up to its fold. It is
# traced with the event-driven time integrator of the suite (marching/compliant.py), continued
# frequency by frequency from the engine's orbit at BRANCH_START.
BRANCH_START = 1.09
BRANCH_OMEGAS = (1.10, 1.15, 1.20, 1.25, 1.30, 1.35)


def coexisting_branch(cli: str, workdir: str, omegas=BRANCH_OMEGAS) -> dict:
    """{"omega", "xmax", "xmin" (= -min x), "cpu_s"}: the contact orbit marched from rest on the
    engine's orbit at BRANCH_START, each frequency starting from the previous orbit at phase 0."""
    from marching.compliant import march_compliant

    t0 = time.perf_counter()
    r = engine.solve(cli, scene_text(BRANCH_START), os.path.join(workdir, "branch"), "start")
    x0, v0 = np.array([r.x[0][0]]), np.array([r.v[0][0]])
    out = dict(omega=[], xmax=[], xmin=[])
    for w in omegas:
        m = march_compliant(system(w), tol=1e-5, samples=256, x0=x0, v0=v0, min_periods=2)
        out["omega"].append(w)
        out["xmax"].append(float(m.x.max()))
        out["xmin"].append(float(-m.x.min()))
        x0, v0 = m.x[:, 0].copy(), m.v[:, 0].copy()
    out = {k: np.array(v) for k, v in out.items()}
    out["cpu_s"] = time.perf_counter() - t0
    return out


# ----------------------------------------------------------------------------- figure


def plot(run: CosimRun, p: Peaks, nonlin: Sweep, linear: Sweep, agr: dict, branch: dict | None = None,
         path: str = FIGURE) -> str:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(3, 1, figsize=(9.5, 11.5), gridspec_kw=dict(height_ratios=[1.0, 1.6, 0.9]))
    ax = axes[0]
    ax.plot(run.t, run.x, lw=0.4, color="C0", label="contact.displacement[0] (PeriodicContact FMU)")
    ax.axhline(GAP, color="k", lw=0.8, ls="--", label=f"stop (clearance {GAP:g})")
    ax.set_xlabel("time [s]")
    ax.set_ylabel("displacement")
    ax2 = ax.twinx()
    ax2.plot(run.t, run.w_driver, color="C3", lw=1.2, label="ramp.frequency (FrequencyRamp FMU)")
    ax2.set_ylabel("driven ω [rad/s]", color="C3")
    ax.set_title("libcosim co-simulation: ramp.frequency → contact.frequency_in "
                 f"(fixed step {run.h * 1e3:.1f} ms, {run.t.size - 1} steps, {run.wall_s:.1f} s wall)", fontsize=9)
    l1, n1 = ax.get_legend_handles_labels()
    l2, n2 = ax2.get_legend_handles_labels()
    ax.legend(l1 + l2, n1 + n2, loc="lower left", fontsize=8)

    ax = axes[1]
    up, lo = p.upper & ~p.at_jump, ~p.upper & ~p.at_jump
    o_up, o_lo = np.argsort(p.omega[up]), np.argsort(p.omega[lo])
    ax.plot(linear.omega, linear.amp, color="0.6", lw=1.2, label="linear (stop removed): CLI solve")
    ax.plot(nonlin.omega[lo][o_lo], nonlin.xmin[lo][o_lo], color="C1", lw=1.6,
            label="with stop: CLI solve at the same ω, −min x (free side)")
    ax.plot(nonlin.omega[up][o_up], nonlin.xmax[up][o_up], color="C2", lw=1.6,
            label="with stop: CLI solve at the same ω, max x (stop side)")
    ax.plot(p.omega[lo], p.value[lo], "o", ms=3.0, mfc="none", color="C1", mew=0.7,
            label="FMU run-up: −x at each minimum")
    ax.plot(p.omega[up], p.value[up], "s", ms=2.6, mfc="none", color="C2", mew=0.7,
            label="FMU run-up: x at each maximum")
    if branch is not None and branch["omega"].size:
        ax.plot(np.concatenate([[BRANCH_START], branch["omega"]]),
                np.concatenate([[nonlin.xmin[np.argmin(np.abs(nonlin.omega - BRANCH_START))]], branch["xmin"]]),
                "--", marker=".", color="C4", lw=1.0,
                label="coexisting stable orbit with contact, −min x\n(time integration; the FMU's run-up stays on it, cold CLI solves do not)")
    ax.axhline(GAP, color="k", lw=0.8, ls="--")
    ax.set_xlabel("ω [rad/s]")
    ax.set_ylabel("peak displacement")
    ax.set_ylim(0, 1.3 * max(linear.amp.max(), branch["xmin"].max() if branch is not None else 0.0))
    ax.set_title(f"envelope vs sweep: 1-DOF oscillator (m={MASS:g}, c={DAMP:g}, k={STIFF:g}, F={FORCE:g} cos ωt) "
                 f"against a compliant stop (clearance {GAP:g}, k_c={K_CONTACT:g}); {SCHEME}, k={STEPS}", fontsize=9)
    ax.legend(fontsize=7.5, loc="upper right")

    ax = axes[2]
    d = np.abs(agr["d"])
    ok, c = agr["ok"], agr["compared"]
    ax.semilogy(p.omega[c], np.maximum(d[c], 1e-12), ".", ms=3, color="C0", label="|FMU peak − CLI peak| / CLI peak")
    if (c & ~ok).any():
        # Above BRANCH_START these are the FMU on the coexisting contact branch, which the cold CLI
        # solve does not return (test_demo.py compares them with the time-integrated branch).
        branch_side = c & ~ok & (p.omega >= BRANCH_START)
        ax.semilogy(p.omega[branch_side], np.maximum(d[branch_side], 1e-12), "x", ms=5, color="C4",
                    label="FMU on the contact branch: vs the cold CLI's contact-free orbit")
        other = c & ~ok & ~branch_side
        if other.any():
            ax.semilogy(p.omega[other], np.maximum(d[other], 1e-12), "x", ms=6, color="C3", label="outside the tolerance")
    for w in run.w_in[jumps(run) + 1]:
        ax.axvline(w, color="C3", lw=0.6, ls=":")
        axes[1].axvline(w, color="C3", lw=0.6, ls=":")
    if jumps(run).size:
        ax.plot([], [], color="C3", lw=0.6, ls=":", label="FMU leaves the contact branch (not compared)")
    o = np.argsort(p.omega)
    ax.semilogy(p.omega[o], agr["tol_rel"][o], "-", color="k", lw=0.7, label="tolerance (sampling + ramp drift)")
    ax.set_xlabel("ω [rad/s]")
    ax.set_ylabel("relative difference")
    lo_d = max(1e-9, float(np.min(np.maximum(d[c], 1e-12)))) / 3 if c.any() else 1e-9
    ax.set_ylim(lo_d, 10.0)
    ax.legend(fontsize=7.5, loc="upper left", ncol=2)
    fig.tight_layout()
    os.makedirs(os.path.dirname(path), exist_ok=True)
    fig.savefig(path, dpi=130)
    plt.close(fig)
    return path


# ----------------------------------------------------------------------------- all of it


@dataclass
class DemoResult:
    run: CosimRun
    peaks: Peaks
    nonlin: Sweep
    linear: Sweep
    agr: dict
    branch: dict | None
    figure: str
    timings: dict


def _start_branch(cli: str, workdir: str):
    """Marches the coexisting branch in a child Python process (it runs on the other core while
    libcosim steps); returns (process, json path)."""
    import subprocess

    out = os.path.join(workdir, "branch.json")
    if os.path.exists(out):
        os.remove(out)
    proc = subprocess.Popen([sys.executable, os.path.abspath(__file__), "--branch", cli, workdir, out],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    return proc, out


def _finish_branch(proc, out: str) -> dict:
    import json

    stdout, stderr = proc.communicate(timeout=600)
    if proc.returncode != 0:
        raise RuntimeError(f"coexisting-branch process failed ({proc.returncode}):\n{stderr[-3000:]}")
    with open(out) as fh:
        d = json.load(fh)
    return {k: (np.asarray(v) if isinstance(v, list) else v) for k, v in d.items()}


def run_demo(cli: str, workdir: str, figure: str = FIGURE, branch: bool = True, **ramp) -> DemoResult:
    """Builds the FMUs, co-simulates, sweeps with the CLI, compares and plots. The coexisting
    branch (branch=True) is marched in a child process while libcosim runs."""
    tm = {}
    os.makedirs(workdir, exist_ok=True)
    t0 = time.perf_counter()
    pc, rp = build_fmus(cli, workdir)
    tm["build_fmus"] = time.perf_counter() - t0
    child = _start_branch(cli, workdir) if branch else None
    try:
        run = cosimulate(pc, rp, **ramp)
    except BaseException:
        if child:
            child[0].kill()
            child[0].communicate()
        raise
    tm["cosim"] = run.wall_s
    t0 = time.perf_counter()
    br = _finish_branch(*child) if child else None
    tm["branch_wait"] = time.perf_counter() - t0
    if br is not None:
        tm["branch_march"] = br["cpu_s"]
    p = peaks(run)
    t0 = time.perf_counter()
    nonlin = cli_sweep(cli, p.omega, workdir, contact=True)
    w_lin = np.linspace(run.w_driver.min(), run.w_driver.max(), 141)
    linear = cli_sweep(cli, w_lin, workdir, contact=False)
    tm["cli_sweeps"] = time.perf_counter() - t0
    agr = agreement(p, nonlin, run)
    t0 = time.perf_counter()
    fig = plot(run, p, nonlin, linear, agr, br, figure) if figure else ""
    tm["plot"] = time.perf_counter() - t0
    return DemoResult(run, p, nonlin, linear, agr, br, fig, tm)


def summary(r: DemoResult) -> str:
    a, p = r.agr, r.peaks
    c = a["compared"]
    d = np.abs(a["d"])[c]
    big = (a["drift_rel"] > a["sampling_rel"])[c]
    lines = [
        f"co-simulation: {r.run.t.size - 1} steps of {r.run.h * 1e3:.3f} ms, ω {r.run.w_driver[0]:.3f} -> "
        f"{r.run.w_driver[-1]:.3f} rad/s ({a['dw_step']:.2e} rad/s per step), {r.timings['cosim']:.1f} s wall",
        f"output discontinuities (orbit switches): {jumps(r.run).size} at ω = "
        f"{', '.join(f'{w:.5f}' for w in r.run.w_in[jumps(r.run) + 1])}; extrema next to them, not compared: "
        f"{int(p.at_jump.sum())}",
        f"extrema compared: {d.size} ({int((p.upper & c).sum())} maxima, {int((~p.upper & c).sum())} minima), "
        f"{int(a['ok'][c].sum())} within tolerance",
        f"max |FMU - CLI| / CLI: {d.max():.2e} (at ω = {p.omega[c][np.argmax(d)]:.4f}); median {np.median(d):.2e}",
        f"tolerance: sampling {a['sampling_rel'].min():.1e} .. {a['sampling_rel'].max():.1e}, "
        f"drift > sampling at {int(big.sum())} extrema",
        f"without the drift windows: max |d| {d[~big].max() if (~big).any() else float('nan'):.2e}",
        f"peak |x|: FMU {p.value.max():.4f} at ω = {p.omega[np.argmax(p.value)]:.4f}, CLI {r.nonlin.amp.max():.4f} "
        f"at ω = {r.nonlin.omega[np.argmax(r.nonlin.amp)]:.4f}; linear {r.linear.amp.max():.4f} "
        f"at ω = {r.linear.omega[np.argmax(r.linear.amp)]:.4f}",
        ("coexisting contact orbit (time integration): " + ", ".join(
            f"ω {w:.2f}: {xm:.3f}" for w, xm in zip(r.branch["omega"], r.branch["xmin"])) if r.branch else
         "coexisting orbit: not computed"),
        "timings [s]: " + ", ".join(f"{k} {v:.2f}" for k, v in r.timings.items()),
        f"figure: {r.figure}",
    ]
    return "\n".join(lines)


def main() -> int:
    cli = engine.cli_path()
    problem = engine.cli_problem(cli)
    if problem:
        print(f"periodic-contact CLI: {problem} (build it or set PC_CLI)", file=sys.stderr)
        return 2
    wd = os.environ.get("PC_FMU_DIR")
    if wd:
        r = run_demo(cli, os.path.join(wd, "demo"))
    else:
        with tempfile.TemporaryDirectory() as tmp:
            r = run_demo(cli, tmp)
    print(summary(r))
    return 0


def _branch_main(cli: str, workdir: str, out: str) -> int:
    import json

    b = coexisting_branch(cli, workdir)
    with open(out, "w") as fh:
        json.dump({k: (v.tolist() if isinstance(v, np.ndarray) else v) for k, v in b.items()}, fh)
    return 0


if __name__ == "__main__":
    if len(sys.argv) == 5 and sys.argv[1] == "--branch":
        sys.exit(_branch_main(*sys.argv[2:]))
    sys.exit(main())
