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
        os.makedirs(d, exist_ok=True)
        return d
    return str(tmp_path_factory.mktemp("pc"))


def pytest_sessionfinish(session, exitstatus):
    if REPORT.rows:
        REPORT.write()
