#!/usr/bin/env bash
# The virtual bench's assets (issue 34): the paper's straight stent on the radial and crush benches with their
# defaults (37 °C, 0.1 mm/s; the radial force read at a vessel of 34 mm, the device's 40.6 oversized by 19 %),
# and the radial-force study: the same bench over wire diameter × number of crowns (rings) as a sweep. Writes
#   assets/bench/straight_stent_radial.{csv,svg,json}, assets/bench/straight_stent_crush.{csv,svg,json} (the
#   tables, charts and bench.json: the sizes the bench reads its forces at),
#   assets/bench/radial_study.csv and assets/bench/radial_study_cof.svg, and
#   assets/bench/straight_stent_lock.{csv,svg,json,png}: the radial bench with the wires' contact on, crimping past
#   the lock (9 mm, 120 diameters per branch for a reading 0.27 mm fine, 30 augmented-Lagrange updates per step so
#   that the struts pressed past the lock stay within the tolerance) and the picture of the locked struts at the
#   closed crimper
# from a release build (`scripts/bench_assets.sh lock` makes the lock's alone); `scripts/docs_tables.py` makes the README's tables from the CSVs. A new measurement needs
# new entries in assets/provenance.json (date, machine, command, sha256), or that script refuses it.
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build --release --quiet
bin=target/release/stentkit
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
mkdir -p assets/bench
lock_bench() {
    "$bin" bench radial designs/straight_stent.yaml --set contact.wires=true --set bench.min_diameter=9 \
        --set bench.diameters=120 --set contact.max_updates=30 -o "$work/lock" --quiet
    cp "$work/lock/radial.csv" assets/bench/straight_stent_lock.csv
    cp "$work/lock/bench.json" assets/bench/straight_stent_lock.json
    cp "$work/lock/charts/radial_force.svg" assets/bench/straight_stent_lock.svg
    closed=$(ls "$work/lock/snapshots" | sed -n 's/^t\([0-9.]*\)_fixed\.stl$/\1/p')
    "$bin" render "$work/lock" --times "$closed" --view x1-x2 --width 900 --force \
        -o assets/bench/straight_stent_lock.png
}
# `scripts/bench_assets.sh lock`: the lock's assets alone.
if [ "${1:-}" = lock ]; then
    lock_bench
    sha256sum assets/bench/straight_stent_lock.*
    exit
fi
"$bin" bench radial designs/straight_stent.yaml --set bench.vessel_diameter=34 -o "$work/radial" --quiet
cp "$work/radial/radial.csv" assets/bench/straight_stent_radial.csv
cp "$work/radial/bench.json" assets/bench/straight_stent_radial.json
cp "$work/radial/charts/radial_force.svg" assets/bench/straight_stent_radial.svg
"$bin" bench crush designs/straight_stent.yaml -o "$work/crush" --quiet
cp "$work/crush/crush.csv" assets/bench/straight_stent_crush.csv
cp "$work/crush/bench.json" assets/bench/straight_stent_crush.json
cp "$work/crush/charts/crush_force.svg" assets/bench/straight_stent_crush.svg
"$bin" sweep designs/straight_stent.yaml --set section.diameter=0.4:0.7:0.1 --set stent.crowns=2,4,6 \
    --set bench.vessel_diameter=34 --bench radial -o "$work/study"
cp "$work/study/sweep.csv" assets/bench/radial_study.csv
cp "$work/study/charts/cof_at_vessel_vs_diameter.svg" assets/bench/radial_study_cof.svg
lock_bench
sha256sum assets/bench/*
