"""Peers side by side (issue 6): our `periodic-contact lcp` against Siconos 4.4's lexicographic Lemke
on the study's rigid-stop LCPs, and the scipy/numpy time marcher against our periodic solve, in
one run (validation/peers/siconos_lemke.py). Writes validation/peers/out/peers.md.

Environment:
  PC_PEERS_SIZES   LCP sizes (default "1024,2048,4096"; Siconos needs minutes at 4096)
  PC_PEERS_OUT     output folder (default validation/peers/out)

Skipped, with the reason, when python3-siconos cannot be installed; the CLI fixture skips (or fails
with PC_REQUIRE_BINARIES=1) when the engine is not built.

Asserted: both solvers solve every LCP; our residual <= 1e-10 and Siconos' tolerance met; the two
solutions agree; the marcher's steady state is our periodic solution; we are faster than Siconos by
the issue's targets (>= 10x at N = 1024 and 2048, >= 20x at 4096), which every measured run
exceeded by 7x or more (see RATIO_FLOOR).
"""
from __future__ import annotations

import os

import pytest

from peers import siconos_lemke

HERE = os.path.dirname(os.path.abspath(__file__))

TOL = 1e-10
# The targets per size.
TARGETS = {1024: 10.0, 2048: 10.0, 4096: 20.0}
# What is asserted: the targets themselves. Measured in two runs (2 cores shared with parallel
# builds, load average 12 and 6-7): Siconos/ours = 73x and 83x at 1024, 188x and 112x at 2048,
# 201x and 204x at 4096 (validation/peers/README.md), i.e. at least 7x, 11x and 10x above the
# targets.
RATIO_FLOOR = dict(TARGETS)


@pytest.mark.engine
def test_siconos_lemke_and_marching_side_by_side(cli):
    sizes = [int(s) for s in os.environ.get("PC_PEERS_SIZES", "1024,2048,4096").split(",") if s]
    out = os.environ.get("PC_PEERS_OUT", os.path.join(HERE, "peers", "out"))
    available, message = siconos_lemke.ensure_siconos(install=True)
    if not available:
        pytest.skip(f"Siconos comparison skipped: {message}")
    res = siconos_lemke.run(sizes, TOL, out, cli=cli)
    print(siconos_lemke.markdown(res))
    for row in res["lcp"]:
        n, ours, sic = row["n"], row["ours"], row["siconos"]
        assert ours["status"] == "solved", f"N = {n}: ours {ours['status']}"
        assert ours["residual"] <= TOL, f"N = {n}: our residual {ours['residual']:.3e}"
        assert sic["ours_checked_by_siconos"]["residual_inf"] <= TOL, f"N = {n}: our z re-checked in numpy"
        assert sic["siconos"]["solved"], f"N = {n}: Siconos info {sic['siconos']['info']}, error {sic['siconos']['lcp_compute_error']:.3e}"
        assert sic["max_z_difference_rel"] <= 1e-8, f"N = {n}: solutions differ by {sic['max_z_difference_rel']:.3e}"
        ratio = row["ratio"]
        assert ratio >= RATIO_FLOOR.get(n, 1.0), f"N = {n}: only {ratio:.1f}x faster than Siconos (target {TARGETS.get(n)}x)"
    for m in res["march"]:
        # Same discrete orbit: the marcher's steady state is the cds/forward periodic solution.
        assert m["difference"] <= 1e-8, f"N = {m['n']}: marching and the periodic solve differ by {m['difference']:.2e}"
