#!/bin/sh
# The whole loop of docs/continuum.md §1.1: the μ(I) law of the column-collapse scenario's grains
# from a simple-shear campaign, the DEM column collapse, and Gerris at level 8 with the law's
# uncertainty band, compared. Usage: scripts/continuum-loop.sh [OUT_DIR] (default loop-out),
# from the repository's root, `grainlaw` and `gerris2D` on the PATH. Each step's wall-clock
# time goes to OUT_DIR/times.txt.
set -eu
out=${1:-loop-out}
mkdir -p "$out"
plan=$(cd "$(dirname "$0")/.." && pwd)/datasets/campaigns/column-collapse-law.toml
cd "$out"
step() { # NAME COMMAND...: run, time, and accept exit 0 (done) or 3 (suspect, files written)
    name=$1; shift
    t0=$(date +%s.%N)
    set +e; "$@"; rc=$?; set -e
    t1=$(date +%s.%N)
    printf '%s %.1f s exit %d\n' "$name" "$(echo "$t1 - $t0" | bc)" "$rc" | tee -a times.txt
    [ "$rc" -eq 0 ] || [ "$rc" -eq 3 ] || exit "$rc"
}
: > times.txt
# 1. the RVE campaign: simple shear of the column's grains, I = 0.04 … 0.5, two seeds -> rve/mu_i_linear_law.json
step rve grainlaw campaign "$plan" --out rve --jobs 2
law=rve/mu_i_law.json
[ -f "$law" ] || law=rve/mu_i_linear_law.json
# 2. the DEM column collapse at the scenario's defaults (a = 6.26, R0 = 20 d)
step dem grainlaw run column-collapse --out dem --allow-suspect
# 3. Gerris at level 8 with the law and its band, against the DEM
step continuum grainlaw continuum column-collapse --law "$law" --dem dem --out col --level 8 --band --jobs 2
