"""Keeps README.md true (issue 26, item 6). Standard library only.

1. Examples: every line of a ```bash block of README.md that calls `periodic-contact …` is run
   as written (with `\\` continuations joined and the trailing `# comment` dropped), in a scratch
   folder that sees the repository's inputs (fmu/, tests/, examples/, validation/ read through
   symlinks) and gets empty output folders (validation/figures, validation/study), so that the
   tracked figures are not rewritten. A nonzero exit or a missing output file (`-o`/`--output`,
   `--hysteresis`) fails. Commands that take minutes run with a quick flag or are skipped, each
   with its reason, both listed in QUICK and SKIP below and printed.
2. Timings: every `<!-- readme-check {json} -->` marker of README.md names a command, what to
   measure and the stated spread; the command is re-run `repeats` times and the check fails when
   the median is outside the spread. Marker keys:
     command   shell text (bash), run in the scratch folder, `periodic-contact` on the PATH;
     measure   "wall" (the command's wall time [s]) or a regex whose first group is the figure,
               searched in the command's stdout + stderr;
     repeats   how many runs (default 3);
     spread    [low, high]: the range the README states for the figure;
     what      what the figure is (printed).

Usage (after `cargo build --release`):
    validation/.venv/bin/python validation/tools/readme_check.py [--examples] [--timings] [--measure]
Without --examples/--timings both parts run. --measure prints each marker's measured min–max
(to regenerate a table) and does not fail on the spread. Exit status 0: all true; 1: something
in the README is not reproduced (listed).
"""

import argparse
import json
import os
import re
import shlex
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
README = ROOT / "README.md"

# Examples run with a documented quick flag instead (substring of the command → replacement).
QUICK = {
    "study accuracy -o validation/study": (
        "study accuracy --quick -o validation/study",
        "the full study takes ~2 min of a quiet machine; --quick (k = 32…256, no peers) runs the same code",
    ),
    "study warmstart -o validation/study": (
        "study warmstart --quick -o validation/study",
        "the full study takes 5–8 min; --quick (k = 128, 512, a 5-point sweep) runs the same code",
    ),
}

# Examples not run, with the reason (substring of the command → reason).
SKIP = {
    "continue fmu/scenes/blade-casing-coarse.toml": "4.4 min of a quiet machine (the coarse blade's branch); the same walk is tested on NLvib 03 and the demo",
    "bench --case blade": "minutes (the blade at k up to 4096 with draws); the table's command",
    "bench --case rigid-stick,rigid-impact,compliant,chain": "minutes (k up to 65 536, 5 members per case); the table's command",
    "bench --case reduced": "k = 8192 takes 11 min; the table's command",
}


def bash_commands(text):
    """The `periodic-contact …` lines of the ```bash blocks, continuations joined, comments dropped."""
    out = []
    in_block = False
    pending = ""
    for line in text.splitlines():
        stripped = line.strip()
        if stripped.startswith("```"):
            in_block = stripped in ("```bash", "```sh") and not in_block
            pending = ""
            continue
        if not in_block:
            continue
        line = pending + line.strip()
        if line.endswith("\\"):
            pending = line[:-1] + " "
            continue
        pending = ""
        command = strip_comment(line)
        if re.match(r"^(\S+=\S+\s+)*periodic-contact(\s|$)", command):
            out.append(command)
    return out


def strip_comment(line):
    """The line without its trailing `# comment` (a `#` outside quotes, after a space)."""
    quote = None
    for i, c in enumerate(line):
        if c in "'\"" and quote in (None, c):
            quote = None if quote else c
        elif c == "#" and quote is None and (i == 0 or line[i - 1] == " "):
            return line[:i].strip()
    return line.strip()


def scratch():
    """A folder that sees the repository's inputs and gets its own output folders."""
    tmp = Path(tempfile.mkdtemp(prefix="readme-check-"))
    for name in ["fmu", "tests", "examples", "include", "src"]:
        (tmp / name).symlink_to(ROOT / name)
    (tmp / "validation").mkdir()
    for child in (ROOT / "validation").iterdir():
        if child.name not in ("figures", "study", "out"):
            (tmp / "validation" / child.name).symlink_to(child)
    for name in ["figures", "study"]:
        # The output folders' tree, empty: the commands' outputs land here, not on tracked files.
        for d in [ROOT / "validation" / name, *(ROOT / "validation" / name).rglob("*")]:
            if d.is_dir():
                (tmp / d.relative_to(ROOT)).mkdir(parents=True, exist_ok=True)
    return tmp


def environment():
    env = dict(os.environ)
    env["PATH"] = f"{ROOT / 'target' / 'release'}{os.pathsep}{env.get('PATH', '')}"
    return env


def outputs(command):
    """The files a command says it writes."""
    words = shlex.split(command)
    files = []
    for flag, value in zip(words, words[1:]):
        if flag in ("-o", "--output", "--hysteresis") and value != "-":
            files.append(value)
    return files


def run(command, cwd, timeout=900):
    start = time.perf_counter()
    p = subprocess.run(["bash", "-c", command], cwd=cwd, env=environment(), capture_output=True, text=True, timeout=timeout)
    return p, time.perf_counter() - start


def check_examples(text, failures):
    tmp = scratch()
    commands = bash_commands(text)
    print(f"== {len(commands)} CLI examples of README.md (in {tmp})")
    for command in commands:
        skip = next((reason for key, reason in SKIP.items() if key in command + "  "), None)
        if skip:
            print(f"SKIP  {command}\n      why: {skip}")
            continue
        for key, (quick, why) in QUICK.items():
            if key in command:
                print(f"QUICK {command}\n      runs: {command.replace(key, quick)} ({why})")
                command = command.replace(key, quick)
        p, wall = run(command, tmp)
        missing = [f for f in outputs(command) if not (tmp / f).exists()]
        if p.returncode != 0 or missing:
            why = f"exit {p.returncode}" if p.returncode else f"missing {missing}"
            failures.append(f"example `{command}`: {why}\n{p.stderr.strip()[-800:]}")
            print(f"FAIL  {command} ({why}, {wall:.1f} s)")
        else:
            print(f"ok    {command} ({wall:.1f} s)")


def markers(text):
    for m in re.finditer(r'<!--\s*readme-check\s+(\{".*?\})\s*-->', text, re.S):
        yield json.loads(m.group(1))


def figure(marker, p, wall):
    if marker.get("measure", "wall") == "wall":
        return wall
    m = re.search(marker["measure"], p.stdout + p.stderr)
    return float(m.group(1)) if m else None


def check_timings(text, failures, measure_only):
    tmp = scratch()
    found = list(markers(text))
    print(f"== {len(found)} timing markers of README.md; load average {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores")
    for marker in found:
        values = []
        for _ in range(int(marker.get("repeats", 3))):
            p, wall = run(marker["command"], tmp)
            if p.returncode != 0:
                failures.append(f"timing `{marker['command']}`: exit {p.returncode}\n{p.stderr.strip()[-800:]}")
                break
            v = figure(marker, p, wall)
            if v is None:
                failures.append(f"timing `{marker['command']}`: the figure /{marker['measure']}/ is not in its output")
                break
            values.append(v)
        if not values:
            continue
        lo, hi = marker["spread"]
        med = statistics.median(values)
        line = f"{marker.get('what', marker['command'])}: measured {min(values):.3g}–{max(values):.3g} (median {med:.3g}) over {len(values)}, README states {lo:g}–{hi:g}"
        inside = lo <= med <= hi
        print(("ok    " if inside or measure_only else "FAIL  ") + line)
        if not inside and not measure_only:
            failures.append(f"timing not reproduced: {line}; command: {marker['command']}")


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--examples", action="store_true", help="run the CLI examples only")
    ap.add_argument("--timings", action="store_true", help="re-run the timing markers only")
    ap.add_argument("--measure", action="store_true", help="print the measured spreads; do not fail on them")
    a = ap.parse_args()
    both = not (a.examples or a.timings)
    if not (ROOT / "target" / "release" / "periodic-contact").exists():
        sys.exit("target/release/periodic-contact is missing: run `cargo build --release` first")
    text = README.read_text()
    failures = []
    if a.examples or both:
        check_examples(text, failures)
    if a.timings or both or a.measure:
        check_timings(text, failures, a.measure)
    if failures:
        print(f"\nREADME.md is not reproduced in {len(failures)} place(s):")
        for f in failures:
            print(f"- {f}")
        sys.exit(1)
    done = [part for part, ran in (("every example ran", a.examples or both), ("every timing within its spread", a.timings or both or a.measure)) if ran]
    print(f"\nREADME.md reproduced: {', '.join(done)}")


if __name__ == "__main__":
    main()
