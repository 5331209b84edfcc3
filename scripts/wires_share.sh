#!/usr/bin/env bash
# Where the straight stent's lock bench spends its time with the wires' contact on (issue 35, speed): samples
# the contact run of `cargo bench --bench wires` (three runs, solver only) with perf and its DWARF call graph and
# adds up the samples under the wires' contact term's entry points (`WireContact` as a `PointTerm`: the coupled
# loads and their tangent, the step limit, the search and updates at a step's start and end, the record at a
# commit) and under the linear algebra (the sparse LU the coupling needs, the block solver while none), against
# all of the process's samples.
#
#   scripts/wires_share.sh            # prints the shares
#   STENTKIT_WRITE_ASSETS=1 scripts/wires_share.sh   # also writes assets/wires_share.csv
#
# Needs `perf` (Debian: linux-perf) and a release build with debug info (the crate's profile has it); the
# sampling itself is `scripts/perf_children.sh`.
set -euo pipefail
cd "$(dirname "$0")/.."
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
scripts/perf_children.sh wires with >"$work/report.txt"
python3 - "$work/report.txt" <<'PY'
import os, re, sys
entry = re.compile(r"WireContact as stentkit::solver::terms::PointTerm>::(coupled|step_limit|prepare|augment|commit)\b")
linear = re.compile(r"stentkit::solver::(sparse::SparseSystem::(factor|new|solve_in_place)|block::BlockSystem::(factor|solve_in_place|new))\b")
parts, algebra = {}, {}
for line in open(sys.argv[1], errors="replace"):
    m = re.match(r"\s*([\d.]+)%\s+([\d.]+)%\s+\S+\s+(.*)$", line)
    if not m:
        continue
    if (e := entry.search(m.group(3))):
        parts[e.group(1)] = parts.get(e.group(1), 0.0) + float(m.group(1))
    elif (e := linear.search(m.group(3))):
        algebra[e.group(1)] = algebra.get(e.group(1), 0.0) + float(m.group(1))
share = sum(parts.values()) / 100.0
print("children shares of the contact term's entry points: " + ", ".join(f"{k} {v:.2f} %" for k, v in sorted(parts.items())))
print("children shares of the linear algebra: " + ", ".join(f"{k} {v:.2f} %" for k, v in sorted(algebra.items())))
print(f"contact term's share of the run's samples: {share:.4f}")
if os.environ.get("STENTKIT_WRITE_ASSETS"):
    with open("assets/wires_share.csv", "w") as f:
        f.write("# perf samples (DWARF call graph, 499 Hz) of `cargo bench --bench wires -- with`, every thread: children shares of the wires' contact term's entry points and of the linear algebra\n")
        f.write("part,percent_of_samples\n")
        for k, v in sorted(parts.items()):
            f.write(f"contact.{k},{v}\n")
        for k, v in sorted(algebra.items()):
            f.write(f"linear.{k},{v}\n")
        f.write(f"contact_share,{share}\n")
    print("wrote assets/wires_share.csv")
PY
