#!/usr/bin/env bash
# The share of the contact term in the crimped straight stent's solver time (issue 33, speed): samples the
# crimped run of `cargo bench --bench contact` (its three runs, solver only) with perf and its DWARF call graph,
# and adds up the samples under the contact term's entry points (`SurfaceContact` as a `PointTerm`: the search,
# law and tangent at the points, the step limit, the Uzawa updates, the checks between points at a commit)
# against all of the process's samples. Sampling, not timers in the hot loop: a timer around every
# point's contact would cost more than the contact (~50 ns against a ~100 ns point).
#
#   scripts/contact_share.sh            # prints the share
#   STENTKIT_WRITE_ASSETS=1 scripts/contact_share.sh   # also writes assets/contact_share.csv
#
# Needs `perf` (Debian: linux-perf) and a release build with debug info (the crate's profile has it).
set -euo pipefail
cd "$(dirname "$0")/.."
cargo bench --bench contact --no-run >/dev/null 2>&1
bin=$(ls -t target/release/deps/contact-* | grep -v '\.d$' | head -n 1)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
perf record -F 499 --call-graph dwarf,16384 -o "$work/perf.data" -- "$bin" crimped >/dev/null 2>"$work/record.log"
perf report -i "$work/perf.data" --children --sort symbol --stdio -g none --percent-limit 0 2>/dev/null >"$work/report.txt"
python3 - "$work/report.txt" <<'PY'
import os, re, sys
# Children shares of the contact term's entry points (a symbol may be listed more than once: its copies add up;
# none of them calls another) against all of the process's samples (the main thread and rayon's workers, which
# run the parallel assembly and the block solver; the bench does nothing but load the design and solve).
entry = re.compile(r"SurfaceContact as stentkit::solver::terms::PointTerm>::(interior|step_limit|prepare|augment|commit)\b")
parts = {}
for line in open(sys.argv[1], errors="replace"):
    m = re.match(r"\s*([\d.]+)%\s+([\d.]+)%\s+\S+\s+(.*)$", line)
    if m and (e := entry.search(m.group(3))):
        parts[e.group(1)] = parts.get(e.group(1), 0.0) + float(m.group(1))
share = sum(parts.values()) / 100.0
print("children shares of all samples: " + ", ".join(f"{k} {v:.2f} %" for k, v in sorted(parts.items())))
print(f"contact share of the solver's samples: {share:.4f}")
if os.environ.get("STENTKIT_WRITE_ASSETS"):
    with open("assets/contact_share.csv", "w") as f:
        f.write("# perf samples (DWARF call graph, 499 Hz) of `cargo bench --bench contact -- crimped`, every thread: children shares of the contact term's entry points\n")
        f.write("part,percent_of_samples\n")
        for k, v in sorted(parts.items()):
            f.write(f"{k},{v}\n")
        f.write(f"contact_share,{share}\n")
    print("wrote assets/contact_share.csv")
PY
