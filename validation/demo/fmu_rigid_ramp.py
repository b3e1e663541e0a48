"""The FMU on a rigid stop follows the exact branch (issue 24 items 3-4): fmpy.simulate_fmu drives
`frequency_in` of the impact oscillator (m = 1, c = 0.1, k = 1, F = cos wt, a rigid stop at 1.5,
plastic impacts; bds1, k = 512) in a ramp W0 -> W1 over N communication steps (one re-solve per
step), and prints the FMU's log lines that say which branch the re-solves follow and where they
jump, with the CPU time.

    python3 validation/demo/fmu_rigid_ramp.py target/release/periodic-contact W0 W1 N

References (tests/branch.rs): the stable impacting orbit's fold at 1.3784287 rad/s (closed form of
src/exact/rigid.rs) and the contact-free orbit's grazing F/|1 - w^2 + icw| = gap at 1.2861349.
"""
from __future__ import annotations

import os
import re
import subprocess
import sys
import tempfile
import time

import numpy as np

SCENE = """[structure]
mass = [[1.0]]
stiffness = [[1.0]]
[damping]
matrix = [[0.1]]
[excitation]
frequency = {w0}
[[force]]
dof = 0
amplitude = 1.0
[[contact]]
dof = 0
gap = 1.5
[discretization]
scheme = "bds1"
steps = 512
[output]
displacement = [0]
"""

JUMP = re.compile(r"jump at t = \S+: the branch ended at a fold \(frequency ([0-9.]+) rad/s\) between frequency ([0-9.]+) and ([0-9.]+)")


def ramp(cli: str, w0: float, w1: float, n: int, workdir: str) -> tuple[list[str], float]:
    """The FMU's log lines over the ramp, and the CPU time of the simulation."""
    from fmpy import simulate_fmu

    scene, fmu = os.path.join(workdir, "impact.toml"), os.path.join(workdir, "impact.fmu")
    with open(scene, "w") as fh:
        fh.write(SCENE.format(w0=w0))
    subprocess.run([cli, "fmu", scene, "-o", fmu], check=True, capture_output=True)
    # Piecewise constant: frequency_in holds w0 + (w1 - w0) i / n over step i.
    times = np.repeat(np.arange(n + 1, dtype=float), 2)[1:]
    values = np.repeat(w0 + (w1 - w0) * np.arange(n + 1) / n, 2)[:-1]
    signal = np.array(list(zip(times, values)), dtype=[("time", float), ("frequency_in", float)])
    lines: list[str] = []

    def logger(env, instance, status, category, message):
        lines.append(message.decode() if isinstance(message, bytes) else str(message))

    t0 = time.process_time()
    simulate_fmu(fmu, fmi_type="CoSimulation", start_time=0.0, stop_time=float(n), step_size=1.0,
                 input=signal, output=["displacement[0]"], debug_logging=True, logger=logger)
    return lines, time.process_time() - t0


def jumps(lines: list[str]) -> list[tuple[float, float, float]]:
    """(fold, frequency before, frequency after) of each jump the log reports."""
    return [tuple(float(g) for g in m.groups()) for m in map(JUMP.search, lines) if m]


def main(cli: str, w0: float, w1: float, n: int) -> int:
    with tempfile.TemporaryDirectory() as d:
        lines, cpu = ramp(cli, w0, w1, n, d)
    for line in lines:
        if "branch" in line:
            print(line)
    print(f"{len(jumps(lines))} jumps; cpu {cpu:.1f} s ({n} re-solves)")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1], float(sys.argv[2]), float(sys.argv[3]), int(sys.argv[4])))
