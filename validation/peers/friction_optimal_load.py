"""The optimal-normal-load curve of the Jenkins damper (issue 25) against the exact event-driven
simulation (validation/peers/friction_exact.py, independent of the crate).

Ours: `periodic-contact continue fmu/scenes/friction-damper.toml --param normal_force --from A
--to B --max-step S --peak-over frequency:WA:WB --polish` (the peak over frequency of the
amplitude at each load N, a 24-point frequency grid refined by golden section, the polished
orbit's exact amplitude). The reference runs the same search (same grid, golden section to
1e-6 of the frequency range, then golden section over N to 1e-4 of the load range between the
sampled least peak's neighbours) on the exact simulation's amplitude. The damper: m = k = 1,
c = 0.1, P = 1, k_t = 2, μ = 0.25 (the shipped scene), so the slip force is 0.25·N.

    PC_CLI=target/release/periodic-contact validation/.venv/bin/python \\
        validation/peers/friction_optimal_load.py [--to 8] [--max-step 0.125] [--out validation/peers/out]

Writes friction_optimal_load.md (table, worst first) and .png (both curves, units) to --out.
"""
from __future__ import annotations

import argparse
import csv
import os
import resource
import subprocess
import sys
import time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
from peers import friction_exact, friction_peer  # noqa: E402

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..")
SCENE = os.path.join(ROOT, "fmu", "scenes", "friction-damper.toml")
MU = 0.25
GRID, PEAK_TOL, LOAD_TOL = 24, 1e-6, 1e-4


def golden(f, a, b, tol, sign):
    """(x, f(x)) at the largest (sign 1) or least (−1) of f on [a, b], bracket narrowed to tol."""
    g = (5 ** 0.5 - 1) / 2
    c, d = b - g * (b - a), a + g * (b - a)
    fc, fd = f(c), f(d)
    while abs(b - a) > tol:
        if sign * fc > sign * fd:
            b, d, fd = d, c, fc
            c = b - g * (b - a)
            fc = f(c)
        else:
            a, c, fc = c, d, fd
            d = a + g * (b - a)
            fd = f(d)
    return (c, fc) if sign * fc > sign * fd else (d, fd)


def exact_amplitude(n, omega):
    if n == 0.0:
        # No slip force: the free linear oscillator |P / (k − mω² + icω)| (the simulation
        # chatters on a zero slip force).
        d = friction_peer.DAMPER
        return abs(d["F"][0] / (d["K"][0][0] - d["M"][0][0] * omega ** 2 + 1j * d["C"][0][0] * omega))
    case = dict(friction_peer.DAMPER, slip=MU * n)
    return float(friction_exact.solve(friction_peer.system(case, omega)).amplitude()[0])


def exact_peak(n, lo, hi):
    grid = np.linspace(lo, hi, GRID)
    amps = [exact_amplitude(n, w) for w in grid]
    i = int(np.argmax(amps))
    if i in (0, GRID - 1):
        return float(grid[i]), amps[i]
    return golden(lambda w: exact_amplitude(n, w), grid[i - 1], grid[i + 1], PEAK_TOL * (hi - lo), 1.0)


def ours(a, out_csv):
    args = [friction_peer.cli_path(), "continue", SCENE, "--param", "normal_force", "--from", str(a.start), "--to", str(a.to),
            "--max-step", str(a.max_step), "--peak-over", f"frequency:{a.low}:{a.high}", "--polish", "--quiet", "--no-plot", "-o", out_csv]
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    proc = subprocess.run(args, capture_output=True, text=True)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if proc.returncode != 0:
        raise RuntimeError(f"{' '.join(args)} failed: {proc.stderr.strip()}")
    with open(out_csv) as f:
        rows = [{k.split(" ")[0]: v for k, v in r.items()} for r in csv.DictReader(f)]
    line = [s for s in proc.stderr.splitlines() if "least peak" in s][0]
    opt_amp = float(line.split("least peak ")[1].split(" ")[0])
    opt_n = float(line.split("normal_force = ")[1].split(" ")[0])
    return rows, (opt_n, opt_amp), after.ru_utime - before.ru_utime, " ".join(args)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--start", type=float, default=0.0)
    ap.add_argument("--to", type=float, default=8.0)
    ap.add_argument("--max-step", type=float, default=0.125)
    ap.add_argument("--low", type=float, default=0.5)
    ap.add_argument("--high", type=float, default=2.5)
    ap.add_argument("--out", default=os.path.join(os.path.dirname(os.path.abspath(__file__)), "out"))
    a = ap.parse_args(argv)
    os.makedirs(a.out, exist_ok=True)
    rows, (opt_n, opt_amp), cpu, command = ours(a, os.path.join(a.out, "friction_optimal_load.csv"))
    t = time.process_time()
    table = []
    for r in rows:
        n = float(r["normal_force"])
        w_ex, amp_ex = exact_peak(n, a.low, a.high)
        amp, w = float(r["amplitude_0"]), float(r["peak_frequency"])
        table.append((abs(amp - amp_ex) / amp_ex, n, amp, amp_ex, w, w_ex, r["polished"]))
    ns = [row[1] for row in table]
    i = int(np.argmin([row[3] for row in table]))
    if 0 < i < len(ns) - 1:
        ex_n, ex_amp = golden(lambda n: exact_peak(n, a.low, a.high)[1], ns[i - 1], ns[i + 1], LOAD_TOL * (a.to - a.start), -1.0)
    else:
        ex_n, ex_amp = ns[i], table[i][3]
    ref_cpu = time.process_time() - t
    lines = [f"# Optimal normal load, Jenkins damper (load average {os.getloadavg()[0]:.1f})", "", f"`{command}`", "",
             f"ours {cpu:.1f} s CPU (the CLI process); the exact reference {ref_cpu:.1f} s CPU", "",
             f"**optimum: ours N = {opt_n:.6f} (μN = {MU * opt_n:.6f}), peak {opt_amp:.9f}; exact N = {ex_n:.6f}, peak {ex_amp:.9f}; "
             f"peak error {abs(opt_amp - ex_amp) / ex_amp:.2e}, N error {abs(opt_n - ex_n) / (a.to - a.start):.2e} of the range**", "",
             "| N | μN | peak (ours) | peak (exact) | relative error | ω peak (ours) | ω peak (exact) | polished |", "|---|---|---|---|---|---|---|---|"]
    for err, n, amp, amp_ex, w, w_ex, pol in sorted(table, reverse=True):
        lines.append(f"| {n:g} | {MU * n:g} | {amp:.9f} | {amp_ex:.9f} | {err:.2e} | {w:.6f} | {w_ex:.6f} | {pol} |")
    text = "\n".join(lines) + "\n"
    with open(os.path.join(a.out, "friction_optimal_load.md"), "w") as f:
        f.write(text)
    print(text)
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(8, 5))
    ax.plot(ns, [row[3] for row in table], "k-", label="exact event-driven simulation")
    ax.plot(ns, [row[2] for row in table], "o", mfc="none", label="periodic-contact continue --peak-over --polish")
    ax.plot([opt_n], [opt_amp], "r*", ms=12, label=f"optimum (ours) N = {opt_n:.4f} N, peak {opt_amp:.5f} m")
    ax.set_xlabel("normal load N [N] (slip force μN, μ = 0.25)")
    ax.set_ylabel("peak over ω ∈ [%g, %g] rad/s of the amplitude of DOF 0 [m]" % (a.low, a.high))
    ax.set_title("Jenkins damper: optimal-normal-load curve")
    ax.legend()
    fig.savefig(os.path.join(a.out, "friction_optimal_load.png"), dpi=110)


if __name__ == "__main__":
    main()
