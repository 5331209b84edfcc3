#!/usr/bin/env bash
# Samples one run of a bench binary with perf and its DWARF call graph (499 Hz, every thread) and prints perf's
# children report by symbol: what `scripts/contact_share.sh` adds up.
#
#   scripts/perf_children.sh BENCH ARG > report.txt     # samples `cargo bench --bench BENCH -- ARG`
#
# Needs `perf` (Debian: linux-perf) and a release build with debug info (the crate's profile has it).
set -euo pipefail
cd "$(dirname "$0")/.."
bench=$1
arg=$2
cargo bench --bench "$bench" --no-run >/dev/null 2>&1
bin=$(ls -t target/release/deps/"$bench"-* | grep -v '\.d$' | head -n 1)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
perf record -F 499 --call-graph dwarf,16384 -o "$work/perf.data" -- "$bin" "$arg" >/dev/null 2>"$work/record.log"
perf report -i "$work/perf.data" --children --sort symbol --stdio -g none --percent-limit 0 2>/dev/null
