"""Hysteresis in the drop-in demo (issue 13, Must show): a run-UP and a run-DOWN of the driver FMU
through the resonance of the demo's oscillator, in libcosim, checked against per-point
continuation (`periodic-contact continue`).

The scene is runup.py's (m = 1, k = 1, c = 0.05, F = 0.2 cos ωt, compliant stop k_c = 10 at
clearance 1; cds, k = 256) with `[output] stability = true`. Its resonance bends into an overhang:
a stable contact branch up to a fold near 1.371 rad/s, an unstable middle branch, and the
contact-free orbit, which touches the stop at ω ≈ 1.092 (a nonsmooth fold where the unstable
branch meets it). So a slow run-up should stay on the contact branch up to ~1.371 and jump down;
a run-down should stay contact-free down to ~1.092 and jump up.

Each co-simulation runs in a child Python process with libcosim's log at trace level: the FMU's
`logEvents` lines come through libcosim's logger on the child's stdout, and the jump lines
("jump at t = ...: the branch ended at a fold (frequency ... rad/s) ...") are read from there.

    cd validation && .venv/bin/python demo/hysteresis.py     # writes figures/demo_hysteresis.png
"""
from __future__ import annotations

import csv
import os
import re
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
VALIDATION = os.path.dirname(HERE)
for p in (VALIDATION, HERE):
    if p not in sys.path:
        sys.path.insert(0, p)

import build_ramp  # noqa: E402
import runup  # noqa: E402
from harness import engine  # noqa: E402

FIGURE = os.path.join(VALIDATION, "figures", "demo_hysteresis.png")
W_LOW, W_HIGH = 0.9, 1.6       # rad/s: below the contact-free orbit's grazing, above the fold
T_RAMP = 900.0                 # s, as the run-up of runup.py
JUMP = re.compile(r"jump at t = ([0-9.eE+-]+): the branch ended at a fold \(frequency ([0-9.eE+-]+) rad/s\) "
                  r"between frequency ([0-9.eE+-]+) and ([0-9.eE+-]+); amplitude ([0-9.eE+-]+) -> ([0-9.eE+-]+)")


def scene_text(omega: float, steps: int = runup.STEPS) -> str:
    text = runup.scene_text(omega).replace("velocity = [0]", "velocity = [0]\nstability = true")
    return text.replace(f"steps = {runup.STEPS}", f"steps = {steps}")


@dataclass
class Run:
    w_in: np.ndarray       # ω each sample was computed with
    x: np.ndarray          # displacement[0]
    v: np.ndarray          # velocity[0]
    mult: np.ndarray       # multiplier (largest Floquet modulus) of the current orbit
    h: float
    wall_s: float
    jumps: list            # (t, fold ω, ω before, ω after, amplitude before, after) from the FMU's log


def _child(pc: str, ramp: str, w0: float, w1: float, out: str) -> int:
    """Runs one co-simulation (libcosim log at trace level on stdout) and saves the samples."""
    import libcosimpy.CosimLogging as logging

    logging.log_output_level(logging.CosimLogLevel.TRACE)
    set_level = logging.log_output_level
    logging.log_output_level = lambda level: None  # runup.cosimulate sets WARNING: keep TRACE
    try:
        run = runup.cosimulate(pc, ramp, w_start=w0, w_end=w1, t_ramp=T_RAMP, extra=("multiplier",))
    finally:
        logging.log_output_level = set_level
    np.savez(out, w_in=run.w_in, x=run.x, v=run.v, mult=run.extra["multiplier"], h=run.h, wall=run.wall_s)
    return 0


def cosimulate(pc: str, ramp: str, w0: float, w1: float, workdir: str) -> Run:
    out = os.path.join(workdir, f"run_{w0:g}_{w1:g}.npz")
    log = os.path.join(workdir, f"run_{w0:g}_{w1:g}.log")
    with open(log, "w") as fh:
        proc = subprocess.run([sys.executable, os.path.abspath(__file__), "--child", pc, ramp, str(w0), str(w1), out],
                              stdout=fh, stderr=subprocess.STDOUT, timeout=900)
    if proc.returncode != 0:
        with open(log) as fh:
            raise RuntimeError(f"co-simulation {w0} -> {w1} failed ({proc.returncode}):\n{fh.read()[-3000:]}")
    d = np.load(out)
    with open(log) as fh:
        jumps = [tuple(float(v) for v in m.groups()) for m in JUMP.finditer(fh.read())]
    return Run(d["w_in"], d["x"], d["v"], d["mult"], float(d["h"]), float(d["wall"]), jumps)


@dataclass
class Branch:
    """A `periodic-contact continue` CSV: frequency, amplitude_0, stable, multiplier (certified
    rows only)."""
    omega: np.ndarray
    amp: np.ndarray
    stable: np.ndarray
    mult: np.ndarray
    stop: str
    uncertified: int       # rows dropped: the certifying solve landed on another orbit, whose amplitude they carry


def continue_branch(cli: str, scene: str, w0: float, w1: float, out: str) -> Branch:
    """Runs the CLI's continuation; a run that stops early (exit 1, "stopped before") still
    writes its CSV, which is used up to where it stopped. Rows with certified = false are dropped:
    their amplitude is that of the orbit the certifying solve landed on, not the branch's (seen
    after the stall near 1.3687 rad/s: 0.23 on a branch at 2.69)."""
    proc = subprocess.run([cli, "continue", scene, "--param", "frequency", "--from", str(w0), "--to", str(w1),
                           "-o", out, "--quiet", "--no-plot"], capture_output=True, text=True, timeout=600)
    if not os.path.exists(out):
        raise engine.EngineError(f"continue {w0} -> {w1}: no CSV ({proc.returncode}): {proc.stderr[-2000:]}")
    with open(out) as fh:
        rows = list(csv.reader(fh))[1:]
    certified = [r for r in rows if r[6] == "true"]
    dropped, rows = len(rows) - len(certified), certified
    col = lambda i: np.array([float(r[i]) for r in rows])  # noqa: E731
    stop = re.search(r"stop: ([^→\n]*)", proc.stdout + proc.stderr)
    return Branch(col(0), col(1), np.array([r[2] == "true" for r in rows]), col(3), stop.group(1).strip() if stop else "", dropped)


def envelope(run: Run, with_tolerance: bool = False):
    """(ω, amplitude[, relative tolerance]): at each local maximum of x, half its difference with
    the mean of the minima just before and just after it, at the maximum's ω. Why the mean: each
    sample is the orbit of its own ω, and the ramp moves by ~2e-3 rad/s in half a period; the two
    minima's mean is the minimum at the maximum's ω to second order (one minimum alone was off by
    8e-4 relative, the drift of the orbit's mean position). Triples across a jump are dropped."""
    x = run.x
    mid = slice(1, -1)
    imax = np.nonzero((x[mid] > x[:-2]) & (x[mid] >= x[2:]))[0] + 1
    imin = np.nonzero((x[mid] < x[:-2]) & (x[mid] <= x[2:]))[0] + 1
    j = np.searchsorted(imin, imax)
    ok = (j >= 1) & (j < imin.size)
    a, p, n = imax[ok], imin[j[ok] - 1], imin[j[ok]]
    jump_steps = np.array([np.argmin(np.abs(run.w_in - w)) for (_, _, _, w, _, _) in run.jumps], dtype=int)
    keep = np.array([not np.any((jump_steps >= lo - 1) & (jump_steps <= hi + 1)) for lo, hi in zip(p, n)], dtype=bool)
    a, p, n = a[keep], p[keep], n[keep]
    w, amp = run.w_in[a], 0.5 * (x[a] - 0.5 * (x[p] + x[n]))
    if not with_tolerance:
        return w, amp
    # A sampled extremum misses the orbit's peak by at most ½|ẍ|(h/2)², and so does the CLI's
    # amplitude (max and min over its k instants, h_cli = T/k). |ẍ| is bounded by the equation of
    # motion at the sample: F + k|x| + k_c max(0, x − gap) + c|v|.
    acc = lambda i: runup.FORCE + runup.STIFF * np.abs(x[i]) + runup.K_CONTACT * np.maximum(0.0, x[i] - runup.GAP) + runup.DAMP * np.abs(run.v[i])  # noqa: E731
    h_cli = 2 * np.pi / w / runup.STEPS
    miss = 0.5 * (acc(a) + 0.5 * (acc(p) + acc(n))) * ((run.h / 2) ** 2 + (h_cli / 2) ** 2)
    return w, amp, 0.5 * miss / amp


# A segment of a continued branch counts as stable when both ends have |μ| ≤ 1 + this. Why not 1:
# at a kink of the discrete map the smoothed monodromy of an orbit between stable neighbours
# (|μ| = 0.89) reads 1.0014 (the up-continuation at 1.36404 rad/s); the unstable middle branch has
# |μ| ≥ 1.05 away from its ends. The count of FMU points matched through such a point is reported.
STABLE_SLACK = 0.01


def _second_difference(b: Branch, i: int) -> float:
    """|A''| at point i of a branch by the divided difference of i-1, i, i+1 (0 at the ends)."""
    if i < 1 or i + 1 >= b.omega.size:
        return 0.0
    w0, w1, w2 = b.omega[i - 1], b.omega[i], b.omega[i + 1]
    if len({w0, w1, w2}) < 3:
        return 0.0
    return abs(2 * ((b.amp[i + 1] - b.amp[i]) / (w2 - w1) - (b.amp[i] - b.amp[i - 1]) / (w1 - w0)) / (w2 - w0))


def on_stable_branch(omega: np.ndarray, amp: np.ndarray, branches: list[Branch]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """For each (ω, A): the relative distance to the nearest amplitude of a STABLE segment of the
    continued branches at that ω (linear interpolation between two consecutive points), that
    amplitude, and the relative error bound of the interpolation, ⅛|A''|Δω² (Δω the segment's
    width, A'' the larger divided difference at its ends; 8e-4 on the contact-free orbit at
    1.28 rad/s, where the continuation steps 0.015 rad/s)."""
    best = np.full(omega.shape, np.inf)
    ref = np.full(omega.shape, np.nan)
    interp = np.zeros(omega.shape)
    for b in branches:
        for i in range(b.omega.size - 1):
            if max(b.mult[i], b.mult[i + 1]) > 1 + STABLE_SLACK or b.omega[i] == b.omega[i + 1]:
                continue
            (w0, a0), (w1, a1) = sorted([(b.omega[i], b.amp[i]), (b.omega[i + 1], b.amp[i + 1])])
            m = (omega >= w0) & (omega <= w1)
            if not m.any():
                continue
            a = np.interp(omega[m], [w0, w1], [a0, a1])
            d = np.abs(amp[m] - a) / a
            better = d < best[m]
            idx = np.nonzero(m)[0][better]
            best[idx], ref[idx] = d[better], a[better]
            curvature = max(_second_difference(b, i), _second_difference(b, i + 1))
            interp[idx] = curvature * (w1 - w0) ** 2 / 8 / a[better]
    return best, ref, interp


@dataclass
class Hysteresis:
    up: Run
    down: Run
    branches: list
    fold_upper: float      # the fold at the contact branch's resonance tip (its largest frequency)
    fold_lower: float      # the fold of the run-down continuation (the contact-free orbit's grazing)
    figure: str
    timings: dict


def run_hysteresis(cli: str, workdir: str, figure: str = FIGURE, steps: int = runup.STEPS) -> Hysteresis:
    """The run-up, the run-down and both continuations of the demo's scene on `steps` instants."""
    tm = {}
    os.makedirs(workdir, exist_ok=True)
    t0 = time.perf_counter()
    name = "demo_oscillator_stop_stability" + ("" if steps == runup.STEPS else f"_k{steps}")
    pc = engine.build_fmu(cli, scene_text(W_LOW, steps), workdir, name)
    ramp = build_ramp.build(os.path.join(workdir, "FrequencyRamp.fmu"))
    scene = os.path.join(workdir, f"{name}.toml")
    up_b = continue_branch(cli, scene, W_LOW, W_HIGH, os.path.join(workdir, "branch_up.csv"))
    down_b = continue_branch(cli, scene, W_HIGH, W_LOW, os.path.join(workdir, "branch_down.csv"))
    tm["continuation"] = time.perf_counter() - t0
    # The run-down starts at W_HIGH on the contact-free orbit (its cold solve there).
    up = cosimulate(pc, ramp, W_LOW, W_HIGH, workdir)
    down = cosimulate(pc, ramp, W_HIGH, W_LOW, workdir)
    tm["cosim_up"], tm["cosim_down"] = up.wall_s, down.wall_s
    import json

    def folds_of(name: str) -> list:
        with open(os.path.join(workdir, f"{name}-events.json")) as fh:
            return [e["frequency"] for e in json.load(fh)["events"] if e["type"] == "fold"]

    # The run-up's walk goes round the whole S-curve to W_HIGH: its upper fold is the resonance tip.
    upper = [f for f in folds_of("branch_up") if f > 1.2]
    folds = [f for f in folds_of("branch_down") if f < 1.2]
    h = Hysteresis(up, down, [up_b, down_b], max(upper) if upper else float(up_b.omega.max()), float(folds[0]) if folds else float("nan"), "", tm)
    if figure:
        h.figure = plot(h, figure)
    return h


def plot(h: Hysteresis, path: str) -> str:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(9.5, 6.5))
    for k, b in enumerate(h.branches):
        # Solid where stable, dashed where unstable, run by run.
        start = 0
        for i in range(1, b.omega.size + 1):
            if i == b.omega.size or b.stable[i] != b.stable[start]:
                sl = slice(start, min(i + 1, b.omega.size))
                ax.plot(b.omega[sl], b.amp[sl], "-" if b.stable[start] else "--", color="0.35", lw=1.3,
                        label=None if k or start else "continuation (periodic-contact continue): stable")
                start = i
    ax.plot([], [], "--", color="0.35", lw=1.3, label="continuation: unstable")
    for run, color, name in ((h.up, "C0", "FMU run-up"), (h.down, "C3", "FMU run-down")):
        w, a = envelope(run)
        ax.plot(w, a, ".", ms=2.5, color=color, label=f"{name} (libcosim, FrequencyRamp → frequency_in): half peak-to-peak")
        for (_, fold, _, w_after, a0, a1) in run.jumps:
            ax.annotate("", xy=(w_after, a1), xytext=(w_after, a0),
                        arrowprops=dict(arrowstyle="->", color=color, lw=1.6))
            ax.text(w_after + 0.005, 0.5 * (a0 + a1), f"{name.split()[1]} jump\nat {fold:.4f} rad/s (FMU log)",
                    color=color, fontsize=8)
    ax.axvline(h.fold_upper, color="0.6", lw=0.6, ls=":")
    ax.axvline(h.fold_lower, color="0.6", lw=0.6, ls=":")
    ax.set_xlabel("excitation frequency ω [rad/s]")
    ax.set_ylabel("amplitude of displacement[0] (half peak-to-peak) [m]")
    ax.set_title("Hysteresis of the drop-in demo: 1-DOF oscillator (m=1, c=0.05, k=1, F=0.2 cos ωt) against a compliant\n"
                 f"stop (clearance 1, k_c=10); cds, k=256; folds of the continuation at {h.fold_lower:.4f} and {h.fold_upper:.4f} rad/s",
                 fontsize=9)
    ax.set_xlim(W_LOW, W_HIGH)
    ax.legend(fontsize=8, loc="upper left")
    fig.tight_layout()
    os.makedirs(os.path.dirname(path), exist_ok=True)
    fig.savefig(path, dpi=130)
    plt.close(fig)
    return path


def summary(h: Hysteresis) -> str:
    lines = [f"continued folds: upper {h.fold_upper:.6f}, lower {h.fold_lower:.6f} rad/s; stops: "
             + "; ".join(b.stop for b in h.branches) + "; uncertified rows dropped: "
             + ", ".join(str(b.uncertified) for b in h.branches)]
    for name, run, fold in (("up", h.up, h.fold_upper), ("down", h.down, h.fold_lower)):
        # Each jump against the continuation's fold, relative: the fold the FMU logs (10 digits) and
        # the farther end of the step it jumps in.
        lines.append(f"run-{name} jumps against the continued fold {fold!r}: " + ", ".join(
            f"logged fold {abs(j[1] - fold) / fold:.1e}, jump step {max(abs(j[2] - fold), abs(j[3] - fold)) / fold:.1e}" for j in run.jumps))
        w, a, tol = envelope(run, with_tolerance=True)
        d, _, interp = on_stable_branch(w, a, h.branches)
        tol = tol + interp
        lines.append(f"run-{name}: {run.w_in.size - 1} steps, {run.wall_s:.1f} s wall; jumps (FMU log): "
                     + ", ".join(f"fold {j[1]:.6f} (ω {j[2]:.6f} -> {j[3]:.6f}), amplitude {j[4]:.4f} -> {j[5]:.4f}" for j in run.jumps)
                     + f"; {w.size} amplitudes, rel. distance to a stable branch max {np.max(d):.2e} (median {np.median(d):.1e}), "
                     f"max distance/tolerance {np.max(d / tol):.2f} (tolerance: sampling + interpolation, {tol.min():.1e} .. {tol.max():.1e}); "
                     f"multiplier {run.mult[1:].min():.4f} .. {run.mult[1:].max():.4f}")
    lines.append("timings [s]: " + ", ".join(f"{k} {v:.1f}" for k, v in h.timings.items()))
    lines.append(f"figure: {h.figure}")
    return "\n".join(lines)


def main() -> int:
    cli = engine.cli_path()
    problem = engine.cli_problem(cli)
    if problem:
        print(f"periodic-contact CLI: {problem} (build it or set PC_CLI)", file=sys.stderr)
        return 2
    with tempfile.TemporaryDirectory() as tmp:
        print(summary(run_hysteresis(cli, os.environ.get("PC_FMU_DIR") or tmp)))
    return 0


if __name__ == "__main__":
    if len(sys.argv) > 1 and sys.argv[1] == "--child":
        sys.exit(_child(sys.argv[2], sys.argv[3], float(sys.argv[4]), float(sys.argv[5]), sys.argv[6]))
    sys.exit(main())
