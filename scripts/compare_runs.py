#!/usr/bin/env python3
"""Compares two run folders, to show that a change left a run's behaviour unchanged (issue 32: every paper
case's history.csv, snapshots and field files byte-identical).

Every file the run wrote is compared byte for byte, except:
- summary.json, which holds wall times;
- run.mcap, whose metadata records the command line (the binary's path, the output folder): its messages
  (topic, log and publish time, bytes) and its metadata other than `command_line` and `design_file` are
  compared instead, with the official `mcap` reader (skipped, and said so, where that is not installed);
- the run's lock and reserve files (`.stentkit-*`).

    python3 scripts/compare_runs.py BASELINE_RUN NEW_RUN

Prints what differs and exits 1 if anything does, 0 otherwise.
"""

import filecmp
import sys
from pathlib import Path

SKIPPED = {"summary.json", "run.mcap"}
LOCATION = {"command_line", "design_file"}


def files(root: Path) -> set:
    return {
        p.relative_to(root).as_posix()
        for p in root.rglob("*")
        if p.is_file() and p.name not in SKIPPED and not p.name.startswith(".stentkit-")
    }


def mcap_content(path: Path):
    from mcap.reader import make_reader

    with open(path, "rb") as f:
        reader = make_reader(f)
        messages = [(c.topic, m.log_time, m.publish_time, m.data) for _, c, m in reader.iter_messages()]
        metadata = [
            (m.name, {k: v for k, v in m.metadata.items() if k not in LOCATION}) for m in reader.iter_metadata()
        ]
    return messages, metadata


def main() -> int:
    a, b = Path(sys.argv[1]), Path(sys.argv[2])
    fa, fb = files(a), files(b)
    problems = [f"only in {a}: {f}" for f in sorted(fa - fb)] + [f"only in {b}: {f}" for f in sorted(fb - fa)]
    common = sorted(fa & fb)
    problems += [f"differs: {f}" for f in common if not filecmp.cmp(a / f, b / f, shallow=False)]
    compared = len(common)
    if (a / "run.mcap").is_file() or (b / "run.mcap").is_file():
        try:
            same = mcap_content(a / "run.mcap") == mcap_content(b / "run.mcap")
            compared += 1
            if not same:
                problems.append("differs: run.mcap (messages or metadata)")
        except ImportError:
            print("run.mcap: not compared (the Python package `mcap` is not installed)")
    for p in problems:
        print(p)
    print(f"{compared} files compared: {'DIFFERENT' if problems else 'identical'}")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
