"""pytest configuration of the validation suite.

Environment:
  PC_CLI               path to the `periodic-contact` executable
                       (default: ../target/release/periodic-contact relative to validation/)
  PC_FMU_DIR           folder where FMUs and scene/result files may be written
                       (default: a pytest temporary folder)
  PC_REQUIRE_BINARIES  "1": a missing CLI is a test FAILURE instead of a skip (set it in CI once
                       the engine builds)
"""
from __future__ import annotations

import os
import sys

import pytest

HERE = os.path.dirname(os.path.abspath(__file__))
if HERE not in sys.path:
    sys.path.insert(0, HERE)

# numpy's OpenBLAS runs a spinning thread per core: beside a second pytest-xdist worker (CI runs two)
# or the engine's own threads they starved each other (a 0.4 s test took 67 s). The suite's
# matrices are small: one thread, set before numpy is first imported.
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import matplotlib  # noqa: E402

matplotlib.use("Agg")

from harness import engine  # noqa: E402
from harness.report import REPORT  # noqa: E402


def require_binaries() -> bool:
    return os.environ.get("PC_REQUIRE_BINARIES", "") not in ("", "0", "false", "no")


@pytest.fixture(scope="session")
def cli() -> str:
    """Path of the CLI; skips (or fails with PC_REQUIRE_BINARIES=1) when it is absent."""
    path = engine.cli_path()
    problem = engine.cli_problem(path)
    if problem:
        msg = (f"periodic-contact CLI not usable: {problem}. Build it (cargo build --release) or set PC_CLI; "
               f"PC_REQUIRE_BINARIES=1 turns this skip into a failure.")
        if require_binaries():
            pytest.fail(msg, pytrace=False)
        pytest.skip(msg)
    return path


@pytest.fixture(scope="session")
def workdir(tmp_path_factory) -> str:
    d = os.environ.get("PC_FMU_DIR")
    if d:
        # One folder per pytest-xdist worker: two workers would otherwise write the same FMUs.
        d = os.path.join(d, os.environ.get("PYTEST_XDIST_WORKER", ""))
        os.makedirs(d, exist_ok=True)
        return d
    return str(tmp_path_factory.mktemp("pc"))


# Modules that fill harness.store for test_zz_figures, which plots what they stored in its process.
SHARED_STORE = ("test_cli", "test_fmu", "test_zz_figures")


@pytest.hookimpl(optionalhook=True)
def pytest_xdist_make_scheduler(config, log):
    """pytest-xdist (`-n 2`, as CI runs it): each test file runs whole on one worker, so that its
    module-scoped fixtures (a co-simulation, a built FMU) are made once, and the files of
    SHARED_STORE run together, in file order (xdist's `--dist loadgroup` marks do nothing under
    pytest 9: it renames `item._nodeid`, which pytest 9 no longer reads)."""
    from xdist.scheduler import LoadFileScheduling

    class ByFile(LoadFileScheduling):
        def _split_scope(self, nodeid: str) -> str:
            path = super()._split_scope(nodeid)
            return "store" if os.path.splitext(os.path.basename(path))[0] in SHARED_STORE else path

    return ByFile(config, log)


def pytest_sessionfinish(session, exitstatus):
    worker_output = getattr(session.config, "workeroutput", None)
    if worker_output is not None:  # a pytest-xdist worker: the controller writes errors.md
        worker_output["report"] = REPORT.as_dict()
        return
    if REPORT.rows:
        REPORT.write()


@pytest.hookimpl(optionalhook=True)
def pytest_testnodedown(node, error):
    """pytest-xdist's controller: a worker's rows and notes join the report it writes."""
    REPORT.merge(getattr(node, "workeroutput", {}).get("report"))
