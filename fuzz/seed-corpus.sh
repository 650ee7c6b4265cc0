#!/usr/bin/env bash
# Seeds the fuzz corpora from the project's own files (and the PEER records if
# PLATEN_RECORDS_DIR is set). Run from fuzz/.
set -euo pipefail
mkdir -p corpus/scenario_json corpus/table_scenario corpus/csv_reader corpus/peer_reader
find ../scenarios -name '*.json' -exec cp {} corpus/scenario_json/ \;
find ../scenarios/multi-axis ../tests/data/multi_axis_poles -name '*.json' -exec cp {} corpus/table_scenario/ \;
for f in ../tests/data/reference/*.csv ../scenarios/sr9/*.csv; do
  head -c 4096 "$f" > "corpus/csv_reader/$(basename "$f")"
done
if [ -n "${PLATEN_RECORDS_DIR:-}" ]; then
  for f in "$PLATEN_RECORDS_DIR"/*.AT2 "$PLATEN_RECORDS_DIR"/*.VT2 "$PLATEN_RECORDS_DIR"/*.DT2; do
    head -c 4096 "$f" > "corpus/peer_reader/$(basename "$f")"
  done
fi
echo "corpus: $(ls corpus/scenario_json | wc -l) scenarios, $(ls corpus/csv_reader | wc -l) csv, $(ls corpus/peer_reader | wc -l) peer"
