#!/usr/bin/env sh
# Remakes the files of this directory with LMGC90 (pylmgc90 built from its sources, see
# ../README.md): pre-processing, 400 steps of 1 ms, then the files copied here.
set -eu
cd "$(dirname "$0")"
work=$(mktemp -d)
cp gen_sample.py command.py "$work"
(cd "$work" && python gen_sample.py > gen.log && python command.py > run.log)
cp "$work/DATBOX/BODIES.DAT" "$work/OUTBOX/BODIES.OUT" "$work"/OUTBOX/DOF.OUT.[12] \
   "$work"/OUTBOX/Vloc_Rloc.OUT.[12] "$work"/lmgc90_reference_[12].csv .
rm -rf "$work"
