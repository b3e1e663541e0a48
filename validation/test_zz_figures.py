"""Figures: one PNG per case in harness.report.FIGURES (validation/out/figures; runs last: file name). Uses whatever the session
produced: the continuous and discrete marchers always, the CLI result and the FMU run when the
engine tests ran."""
import os

import pytest

from harness import store
from harness.cases import CASES, continuous, discrete
from harness.plots import plot_case


@pytest.mark.parametrize("name", list(CASES))
def test_figure(name):
    case = CASES[name]
    run = case.fmu_run
    ref = continuous(name)
    disc = discrete(name, run.scheme, run.pairing, run.steps)
    eng = store.ENGINE.get((name, run.label))
    path = plot_case(case, ref, discrete=disc, engine=eng, fmu=store.FMU.get(name))
    assert os.path.getsize(path) > 10_000
