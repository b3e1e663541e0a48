"""The cost–accuracy curve of issue 23 (validation/RECORD.md "The cost–accuracy curve"): error against CPU of the
explicit march and of ours (`auto`, `auto` + polish), one panel per march_bench output.

    validation/.venv/bin/python validation/march_curve_plot.py out/march-bench/rigid-massless-boundary-2300.txt \
        out/march-bench/compliant-massless-boundary-2300.txt -o validation/figures/march-curve.png

A panel may join files with '+' (e.g. the march of one run and ours of another).
The set-up (read + reduce, the '# scene ... setup cpu' line) is added to every CPU: end to end.
"""
import argparse
import re

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt


def parse(paths):
    setup, march, ours, polish = 0.0, [], [], []
    for line in (line for path in paths.split("+") for line in open(path)):
        m = re.search(r"setup cpu ([0-9.]+) s", line)
        if m:
            setup = float(m.group(1))
        f = line.split()
        # Columns: method run setting k_or_N march_tol periods converged error cpu_s wall_s.
        if len(f) >= 10 and f[0] == "march" and f[7] != "nan":
            march.append((float(f[7]), float(f[8]), f[3], f[4]))
        elif len(f) >= 10 and f[0] == "ours" and f[7] != "nan":
            (polish if f[1] == "auto+polish" else ours).append((float(f[7]), float(f[8]), f[2]))
    return setup, march, ours, polish


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("files", nargs="+")
    ap.add_argument("-o", "--output", required=True)
    a = ap.parse_args()
    fig, axes = plt.subplots(1, len(a.files), figsize=(6 * len(a.files), 4.5), squeeze=False)
    for ax, path in zip(axes[0], a.files):
        setup, march, ours, polish = parse(path)
        if march:
            ax.loglog([setup + c for _, c, _, _ in march], [e for e, _, _, _ in march], "o", label="explicit march (N = 1024 … 32768)")
        if ours:
            ax.loglog([setup + c for _, c, _ in ours], [e for e, _, _ in ours], "s", label="ours: auto at 1e-2 … 1e-6")
        if polish:
            ax.loglog([setup + c for _, c, _ in polish], [e for e, _, _ in polish], "*", ms=12, label="ours: auto + polish")
        ax.set_xlabel(f"CPU end to end [s] (set-up {setup:.1f} s included)")
        ax.set_ylabel("max error / largest peak-to-peak [-]")
        ax.set_title(path.split("+")[0].split("/")[-1].removesuffix(".txt"))
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(a.output, dpi=110)


if __name__ == "__main__":
    main()
