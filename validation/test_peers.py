"""Peers side by side (issues 6 and 12): Siconos 4.4's lexicographic Lemke against ours on the SAME
LCPs -- the rigid stop with sticking, the two-stop chain and the compliant stop, exported by
`periodic-contact solve SCENE --export-lcp` -- and the scipy/numpy time marcher against our
periodic solve, in one run (validation/peers/siconos_lemke.py). Writes validation/peers/out/peers.md.

Ours is timed twice: `solve` (the scene's `timing_s.lcp`: shooting on the step map, certified on
the LCP, with its fallback) and `lcp FILE.dat` (the raw exported LCP, no step map). Every z -- ours
(both) and Siconos' -- goes through the same numpy check on the exported (M, q).

Environment (the defaults are CI's: about a minute for this file; the full run of the README is
PC_PEERS_SIZES=1024,2048,4096 PC_PEERS_MULTI_SIZES=1024,2048,4096 PC_PEERS_RANDOM_SIZES=2048,
about 20 min because Siconos needs minutes at N = 4096):
  PC_PEERS_SIZES         N of the rigid stop (default "1024,2048"; .ci/run sets "1024")
  PC_PEERS_MULTI_SIZES   N of the chain (k = N/2) and of the compliant stop (default "1024";
                         Siconos: ~6 s and ~2.5 s at 1024, ~70 s and ~17 s at 2048)
  PC_PEERS_RANDOM_SIZES  N of one random member of each family (default "": none)
  PC_PEERS_CASES         some of rigid,chain,compliant (default all)
  PC_PEERS_SEED          seed of the random members (default 1)
  PC_PEERS_OUT           output folder (default validation/peers/out)

Skipped, with the reason, when python3-siconos cannot be installed; the CLI fixture skips (or fails
with PC_REQUIRE_BINARIES=1) when the engine is not built.

Asserted, on every LCP: our `solve` and our `lcp` both solve it, and both z pass the numpy
certificate ||min(z, Mz+q)||_inf <= 1e-10 max(1, ||q||_inf) on the exported (M, q); they agree to
1e-8 (two different algorithms: shooting on the step map and pivoting on the matrix). Where
Siconos' answer passes the same certificate it agrees with ours to 1e-8; on the rigid stop and the
compliant stop it must pass (it does: residuals 1e-14..1e-13). On the chain Siconos' Lemke ends
above 1e-10 (2.8e-10 at N = 1024, 5.4e-9 at 2048: reported, not asserted). Speed (Siconos time /
ours, solver times only): the issue's >= 100x for `solve` on the rigid stop and the chain at every
size run (measured 660x..4500x at N = 1024), >= 2x on the compliant stop (measured 55x at 1024,
15x at 2048 where shooting falls back to Lemke); for the raw `lcp` on the rigid stop the former
targets >= 10x at N <= 2048 and >= 20x at 4096 (measured 50-60x at 1024, 200x at 4096), and never
slower than Siconos on the other cases.
"""
from __future__ import annotations

import os

import pytest

from peers import siconos_lemke

HERE = os.path.dirname(os.path.abspath(__file__))

TOL = 1e-10
AGREE = 1e-8
# Siconos time / our `solve` LCP time: the 100x on the rigid stop and the chain; the
# compliant stop has no target, 2x is far below what was measured (15x, Lemke fallback at 2048).
SOLVE_FLOOR = {"rigid": 100.0, "chain": 100.0, "compliant": 2.0}
# Siconos time / our raw `lcp FILE.dat`: issue 6's targets on the rigid stop, else not slower.
LCP_FLOOR_RIGID = {1024: 10.0, 2048: 10.0, 4096: 20.0}
# Peers whose Lemke reaches 1e-10 on these cases in every run (residuals 1e-14..1e-13).
SICONOS_MUST_SOLVE = ("rigid", "compliant")


def _sizes(name: str, default: str) -> list[int]:
    return siconos_lemke.sizes_arg(os.environ.get(name, default))


@pytest.mark.engine
def test_siconos_lemke_and_marching_side_by_side(cli):
    out = os.environ.get("PC_PEERS_OUT", os.path.join(HERE, "peers", "out"))
    cases = [c for c in os.environ.get("PC_PEERS_CASES", ",".join(siconos_lemke.CASES)).split(",") if c]
    available, message = siconos_lemke.ensure_siconos(install=True)
    if not available:
        pytest.skip(f"Siconos comparison skipped: {message}")
    res = siconos_lemke.run(_sizes("PC_PEERS_SIZES", "1024,2048"), TOL, out, cli=cli,
                            multi_sizes=_sizes("PC_PEERS_MULTI_SIZES", "1024"),
                            random_sizes=_sizes("PC_PEERS_RANDOM_SIZES", ""), cases=cases,
                            seed=int(os.environ.get("PC_PEERS_SEED", "1")))
    print(siconos_lemke.markdown(res))
    assert res["lcp"], "no LCP was compared"
    for row in res["lcp"]:
        what = f"{row['case']} ({row['member']}) N = {row['n']}"
        w = row["check"]
        assert "timeout_s" not in w, f"{what}: Siconos stopped after {w.get('timeout_s')} s"
        ch, d, sic = w["checks"], w["differences"], w["siconos"]
        assert row["solve"]["status"] == "solved", f"{what}: our solve {row['solve']['status']} ({row['solve']['full_path']})"
        assert row["lcp"]["status"] == "solved", f"{what}: our lcp {row['lcp']['status']}"
        for ours in ("solve", "lcp"):
            assert ch[ours]["certified"], f"{what}: our {ours} z fails the numpy check, residual {ch[ours]['residual_rel']:.3e}"
        assert d["solve-lcp"] <= AGREE, f"{what}: our solve and our lcp differ by {d['solve-lcp']:.3e}"
        if row["case"] in SICONOS_MUST_SOLVE:
            assert sic["solved"] and ch["siconos"]["certified"], \
                f"{what}: Siconos info {sic['info']}, residual {ch['siconos']['residual_rel']:.3e}"
        if ch["siconos"]["certified"]:
            assert d["siconos-solve"] <= AGREE, f"{what}: Siconos and our solve differ by {d['siconos-solve']:.3e}"
        floor = SOLVE_FLOOR[row["case"]]
        assert row["ratio_solve"] >= floor, f"{what}: Siconos/solve only {row['ratio_solve']:.1f}x (floor {floor}x)"
        lcp_floor = LCP_FLOOR_RIGID.get(row["n"], 1.0) if row["case"] == "rigid" else 1.0
        assert row["ratio_lcp"] >= lcp_floor, f"{what}: Siconos/lcp only {row['ratio_lcp']:.1f}x (floor {lcp_floor}x)"
    for m in res["march"]:
        # Same discrete orbit: the marcher's steady state is the cds/forward periodic solution.
        assert m["difference"] <= 1e-8, f"N = {m['n']}: marching and the periodic solve differ by {m['difference']:.2e}"
