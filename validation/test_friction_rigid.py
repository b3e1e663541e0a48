"""Coulomb friction with a rigid plastic stop (issue 25, "Den Hartog … with stops" read as a
unilateral stop): the reference simulation validation/peers/friction_rigid_exact.py against closed
forms (the departure from the stop, Ω t_d = arccos((k g − μN)/F); μN = 0 is the impact
oscillator's, src/formulation.md §6.3) and friction_exact.py (a stop out of reach); then, given the
CLI (PC_CLI), the crate's plain LCP converging to it at first order and its frictionless rigid
polish meeting it. The stick–slip polish with rigid stops is checked against its numbers in
tests/friction_polish_contact.rs.
"""
from __future__ import annotations

import math
import os

import pytest

from peers import friction_rigid_exact as fr


def test_departure_from_the_stop_meets_the_closed_form():
    for name, err in fr.departure_errors():
        assert err < 1e-10, f"{name}: {err:.2e}"


def test_a_stop_out_of_reach_gives_the_friction_orbit():
    assert fr.out_of_reach_error() < 1e-9


@pytest.mark.engine
@pytest.mark.skipif(not os.environ.get("PC_CLI"), reason="needs the CLI: PC_CLI=…/periodic-contact")
def test_plain_lcp_converges_to_the_reference_at_first_order():
    for name, e256, e512, polished in fr.lcp_errors():
        assert 0.8 < math.log2(e256 / e512) < 1.2, f"{name}: {e256:.3e} → {e512:.3e}"
        assert polished is None or polished < 1e-10, f"{name}: the rigid polish {polished:.2e}"
