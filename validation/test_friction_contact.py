"""Friction contacts together with a compliant unilateral stop (issue 25): the random family of
chains through the CLI's polish against the event-driven simulation
(validation/peers/friction_contact_exact.py), opt-in: PC_FRICTION_CONTACT_FAMILY=<cases> (seed 2027;
about a minute per case at load 15, mostly the LCPs at k = 512).
"""
from __future__ import annotations

import os

import pytest

from peers import friction_contact_family


@pytest.mark.engine
@pytest.mark.skipif(not os.environ.get("PC_FRICTION_CONTACT_FAMILY"), reason="opt-in: PC_FRICTION_CONTACT_FAMILY=<cases>")
def test_random_family_with_a_stop_polishes_exactly_or_falls_back(cli):
    rows = friction_contact_family.family(int(os.environ["PC_FRICTION_CONTACT_FAMILY"]), 2027, cli)
    for err, desc, status, why, _, touches in rows:
        print(f"{err:.2e} {status} {desc} stop events {touches} {why[:160]}")
    # A polished orbit is exact; a fallback says why (the LCP's orbit is kept).
    assert all(err <= 1e-8 for err, _, status, _, _, _ in rows if status == "polished")
    assert all(why for _, _, status, why, _, _ in rows if status != "polished")
