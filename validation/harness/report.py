"""A registry of measured numbers, written by the tests and dumped to errors.md in FIGURES at the end
of the pytest session (conftest.py)."""
from __future__ import annotations

import datetime
import os
from dataclasses import asdict, dataclass, field

VALIDATION = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
# Where the tests write figures and errors.md: validation/out/figures (ignored by git), so that a
# test run leaves the clone clean. PC_FIGURES=validation/figures regenerates the committed ones.
FIGURES = os.path.abspath(os.environ.get("PC_FIGURES") or os.path.join(VALIDATION, "out", "figures"))


@dataclass
class Row:
    case: str
    what: str           # e.g. "cli cds/forward k=512 vs rigid event-driven"
    max_err: float | None = None
    rms_err: float | None = None
    tol: float | None = None
    impulse: str = ""   # impulse per period (value and reference)
    onset: str = ""     # phase of the first impact
    cost: str = ""      # periods / CPU time / solve time
    status: str = ""


@dataclass
class Report:
    rows: list[Row] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)

    def add(self, row: Row) -> None:
        self.rows.append(row)

    def note(self, text: str) -> None:
        if text not in self.notes:
            self.notes.append(text)

    def as_dict(self) -> dict:
        """Plain lists and dicts: what pytest-xdist carries from a worker to the controller."""
        return {"rows": [asdict(r) for r in self.rows], "notes": list(self.notes)}

    def merge(self, data: dict | None) -> None:
        if data:
            self.rows += [Row(**r) for r in data["rows"]]
            for n in data["notes"]:
                self.note(n)

    def markdown(self) -> str:
        def f(v):
            return "" if v is None else f"{v:.3e}"

        out = ["# Validation errors and costs", "",
               f"Written by `pytest` on {datetime.datetime.now().isoformat(timespec='seconds')} "
               f"({len(self.rows)} rows). Errors are relative to the peak-to-peak amplitude of the reference; "
               "`tol` is the asserted bound. Costs: marching periods and CPU time (`time.process_time`), "
               "periodic solve time from the result's `timing_s.total`.", "",
               "| case | comparison | max err | rms err | tol | impulse/period | first impact (t/T) | cost | status |",
               "|---|---|---|---|---|---|---|---|---|"]
        for r in self.rows:
            out.append(f"| {r.case} | {r.what} | {f(r.max_err)} | {f(r.rms_err)} | {f(r.tol)} | {r.impulse} | "
                       f"{r.onset} | {r.cost} | {r.status} |")
        if self.notes:
            out += ["", "## Notes", ""] + [f"- {n}" for n in self.notes]
        return "\n".join(out) + "\n"

    def write(self, path: str | None = None) -> str:
        path = path or os.path.join(FIGURES, "errors.md")
        os.makedirs(os.path.dirname(path), exist_ok=True)
        with open(path, "w") as fh:
            fh.write(self.markdown())
        return path


REPORT = Report()
