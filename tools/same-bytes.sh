#!/usr/bin/env bash
# Byte-identity check for refactors: runs a `platen` binary over every shipped scenario and the
# README's workflows (SR9 compare with figures and report, the paper's identification programme,
# sweeps, generators, model, schema, a set of bad inputs) and writes every output, stdout, stderr
# and exit code into one folder. Two folders made by two binaries must be identical:
#
#   tools/same-bytes.sh OLD_BINARY /tmp/before
#   tools/same-bytes.sh target/release/platen /tmp/after
#   diff -r /tmp/before /tmp/after && echo "same bytes"
#
# With PLATEN_RECORDS_DIR set, the record scenarios (Tarzana, El Centro) are included too.
set -euo pipefail
bin=$(realpath "$1")
out=$(realpath -m "$2")
cd "$(dirname "$0")/.."
rm -rf "$out"
mkdir -p "$out"

# run NAME ARGS…: stdout, stderr and exit code of one invocation, into $out/NAME.{out,err,rc}.
run() {
  local name=$1
  shift
  set +e
  "$bin" "$@" >"$out/$name.out" 2>"$out/$name.err"
  echo $? >"$out/$name.rc"
  set -e
}

records=$(ls scenarios/*.json scenarios/sr9/*.json scenarios/specimen/*.json scenarios/paper-tests/*/*.json)
for s in $records; do
  if grep -q '"ground_motion"\|elcentro' "$s" && [ -z "${PLATEN_RECORDS_DIR:-}" ]; then
    continue
  fi
  name=$(echo "${s#scenarios/}" | tr '/' '_')
  run "simulate_${name}_csv" simulate "$s" --out "$out/${name}.csv"
  run "simulate_${name}_json" simulate "$s" --json
  run "simulate_${name}_text" simulate "$s"
  run "generate_excitation_${name}" generate excitation "$s" --out "$out/${name}.excitation.csv"
done

# Recorded-like data and the paper's identification programme (seed 3, as the README says).
recdir="$out/recorded"
mkdir -p "$recdir"
manifest="$out/manifest.json"
{
  echo '{"tests": ['
  first=1
  for s in scenarios/paper-tests/*/*.json; do
    p=$(basename "$(dirname "$s")")
    n=$(basename "$s" .json)
    f="$recdir/${p}_${n}.csv"
    run "generate_recorded_${p}_${n}" generate recorded "$s" --seed 3 --out "$f"
    pmpa=${p%MPa}
    [ $first = 1 ] || echo ','
    first=0
    printf '{"file": "%s", "pressure_mpa": %s, "name": "%s"}' "$f" "$pmpa" "$n"
  done
  echo ']}'
} >"$manifest"
run identify_json identify --manifest "$manifest" --json
run identify_text identify --manifest "$manifest"
run identify_plot identify --manifest "$manifest" --plot "$out/identify-figures" --report "$out/identify.html"
run identify_files_json identify "$recdir"/13.8MPa_S9.csv "$recdir"/13.8MPa_T4.csv "$recdir"/13.8MPa_S6.csv --pressure-mpa 13.8 --json

# The SR9 check: compare with figures and report, and a window.
run compare_sr9_json compare scenarios/sr9/sr9-forward.json --recorded scenarios/sr9/sr9-recorded.csv --json
run compare_sr9_text compare scenarios/sr9/sr9-forward.json --recorded scenarios/sr9/sr9-recorded.csv
run compare_sr9_plot compare scenarios/sr9/sr9-forward.json --recorded scenarios/sr9/sr9-recorded.csv \
  --plot "$out/sr9-figures" --report "$out/sr9.html"
run compare_sr9_window compare scenarios/sr9/sr9-forward.json --recorded scenarios/sr9/sr9-recorded.csv \
  --window 5,9 --json --plot "$out/sr9-window-figures"
run compare_s9_inverse compare scenarios/paper-tests/13.8MPa/S9.json --recorded "$recdir/13.8MPa_S9.csv" \
  --json --plot "$out/s9-figures" --report "$out/s9.html"
run generate_recorded_sr9 generate recorded scenarios/sr9/sr9-motion.json --seed 1 --out "$out/sr9-rec.csv"

# Sweeps: every axis kind, forward and inverse.
run sweep_forward sweep scenarios/sr9-like-sine-force.json --scale 0.5,1,1.5 --pressure-mpa 6.9,13.8 \
  --set identified.coulomb_force_n=20e3,25e3 --out "$out/sweep-forward.csv" --json
run sweep_full sweep scenarios/full-model-large-stroke.json --scale 0.8,1.2 --set full.strut_area_m2=0.14,0.16 --json
run sweep_inverse sweep scenarios/s9-sine-motion.json --scale 0.5,2 --pressure-mpa 0,13.8 --json
run sweep_plain sweep scenarios/paper-forward-force.json --out "$out/sweep-plain.csv"
run sweep_plot sweep scenarios/sr9-like-sine-force.json --scale 0.5,1,1.5 --pressure-mpa 6.9,13.8 \
  --plot "$out/sweep-figures" --width 1000
run simulate_plot simulate scenarios/paper-forward-force.json --json --plot "$out/simulate-figures" \
  --png-scale 0.5

# The closed loop, planning and the model's loop description (issue 27's refactor moves their
# printing into the libraries).
for s in scenarios/table-system/wn10g-closed-loop.json; do
  name=$(basename "$s" .json)
  run "simulate_${name}_csv" simulate "$s" --out "$out/${name}.csv"
  run "simulate_${name}_json" simulate "$s" --json
  run "simulate_${name}_text" simulate "$s"
  run "model_scenario_${name}_json" model --scenario "$s" --json
  run "model_scenario_${name}_text" model --scenario "$s" --plot "$out/${name}-bode"
done
run model_system_json model --system lhpost-2008 --json
run model_system_text model --system lhpost-2008
run generate_wn10g_target generate excitation scenarios/table-system/wn10g-closed-loop.json --out "$out/wn10g-target.csv"
run plan_wn10g_text plan scenarios/table-system/wn10g-closed-loop.json --target "$out/wn10g-target.csv" \
  --out "$out/wn10g-drive.csv" --iterations 3 --plot "$out/wn10g-plan" --report "$out/wn10g-plan.html"
run plan_wn10g_json plan scenarios/table-system/wn10g-closed-loop.json --target "$out/wn10g-target.csv" \
  --out "$out/wn10g-drive2.csv" --iterations 3 --json
# Any-record identification: a mixed day of records (its manifest's paths are relative to it).
run identify_mixed_json identify --manifest tests/data/any-record/mixed-day-manifest.json --json
run identify_mixed_text identify --manifest tests/data/any-record/mixed-day-manifest.json \
  --report "$out/mixed.html"
run identify_records_json identify tests/data/any-record/eq-lab.csv tests/data/any-record/wn-lab.csv \
  --columns tests/data/any-record/columns.json --json

# Model and schema.
for form in identified full; do
  for p in 0 6.9 13.8; do
    run "model_${form}_${p}_json" model --form $form --pressure-mpa $p --json
    run "model_${form}_${p}_text" model --form $form --pressure-mpa $p
  done
done
run schema schema

# Bad input: messages and exit codes.
bad="$out/bad"
mkdir -p "$bad"
echo '{' >"$bad/truncated.json"
echo '{"model": {"preset": "lhpost-2008"}, "excitation": {"sine_force": {"amplitude_n": 1e5, "frequency_hz": 0.5}}, "duration_s": 2, "wat": 1}' >"$bad/unknown.json"
echo '{"model": {"preset": "lhpost-2008", "identified": {"effective_mass_kg": -1}}, "excitation": {"sine_force": {"amplitude_n": 1e5, "frequency_hz": 0.5}}, "duration_s": 2}' >"$bad/negative-mass.json"
echo '{"model": {"preset": "lhpost-2008"}, "excitation": {"sine_force": {"amplitude_n": 1e5, "frequency_hz": 0.5}}, "integrator": {"method": "rk4", "step_s": 0}, "duration_s": 2}' >"$bad/zero-step.json"
printf 't_s,force_n\n0,0\n0.001,1\n0.001,2\n' >"$bad/dup.csv"
echo '{"model": {"preset": "lhpost-2008"}, "excitation": {"force_csv": "dup.csv"}}' >"$bad/dup-times.json"
printf 't_s,u_m\n0,0\n0.001,nan\n' >"$bad/nan.csv"
echo '{"model": {"preset": "lhpost-2008"}, "excitation": {"motion_csv": "nan.csv"}}' >"$bad/nan-motion.json"
for f in truncated unknown negative-mass zero-step dup-times nan-motion; do
  run "bad_$f" simulate "$bad/$f.json" --out "$bad/$f.csv"
done
run bad_compare_missing compare scenarios/sr9/sr9-forward.json --recorded "$bad/none.csv"
run bad_identify_missing identify "$bad/none.csv"
run bad_sweep_axis sweep scenarios/sr9-like-sine-force.json --set identified.nonsense=1

# identify --system: the loop identified from what labs record (the shipped synthetic records
# of tests/data), with a base, figures, a column map, and its bad inputs.
d=tests/data/system_ident
t=tests/data/small_table
run sys_three_json identify --system $d/wn-a.csv $d/chirp.csv $d/wn-b.csv --json
run sys_three_text identify --system $d/wn-a.csv $d/chirp.csv $d/wn-b.csv
run sys_base_json identify --system $d/wn-a.csv $d/chirp.csv $d/wn-b.csv --base $d/base.json --json
run sys_one_json identify --system $d/wn-a.csv --json
run sys_plot_json identify --system $d/wn-a.csv $d/wn-b.csv --json --plot "$out/sys-fig"
run sys_small_json identify --system $t/wn.csv $t/sweep.csv $t/eq4.csv --columns $t/columns.json --json
run sys_area_json identify --system $t/wn.csv $t/eq4.csv --columns $t/columns.json --area-m2 0.01 --json
run sys_empty identify --system --manifest scenarios/paper-tests/manifest.json
run sys_missing identify --system $d/missing-command.csv --json
run sys_nofile identify --system /nonexistent.csv
run sys_bad_base identify --system $d/wn-a.csv --base scenarios/paper-tests/manifest.json --json
run sys_no_drive identify --system $t/no-drive.csv --columns $t/columns.json
run sys_const identify --system $t/constant-command.csv --columns $t/columns.json --json

# Multi-axis tables (issue 53 puts them on the one stack): every shipped multi-axis and
# table-system scenario through simulate (CSV, JSON, text), generate excitation and model, a
# forward run's figures, an LHPOST6 closed loop of generated sines (no records needed) and its
# three-component plan, and with the records the shipped three-component plan.
for s in scenarios/multi-axis/*.json scenarios/table-system/northridge-*.json; do
  if grep -q '"ground_motion"' "$s" && [ -z "${PLATEN_RECORDS_DIR:-}" ]; then
    continue
  fi
  name=$(echo "${s#scenarios/}" | tr '/' '_')
  run "simulate_${name}_csv" simulate "$s" --out "$out/${name}.csv"
  run "simulate_${name}_json" simulate "$s" --json
  run "simulate_${name}_text" simulate "$s"
  run "generate_excitation_${name}" generate excitation "$s" --out "$out/${name}.excitation.csv"
  run "model_scenario_${name}_json" model --scenario "$s" --json
  run "model_scenario_${name}_text" model --scenario "$s"
done
run simulate_multi_axis_plot simulate scenarios/multi-axis/forward.json --json --plot "$out/multi-axis-figures"
# A run longer than the figures' 2 200 envelope points (bucketed), to Parquet and to CSV.
run simulate_tower_inverse_plot simulate scenarios/multi-axis/tower-inverse.json --json \
  --out "$out/tower-inverse.parquet" --plot "$out/tower-inverse-figures"
run simulate_tower_inverse_plot_text simulate scenarios/multi-axis/tower-inverse.json \
  --out "$out/tower-inverse-2.csv" --plot "$out/tower-inverse-figures-2"
run simulate_multi_axis_pressure simulate scenarios/multi-axis/forward.json --pressure-mpa 10
six="$out/six"
mkdir -p "$six"
cat >"$six/lhpost6-sines.json" <<'JSON'
{"name": "lhpost6 sines", "table": {"preset": "lhpost6"}, "duration_s": 4.0,
 "excitation": {"sine_motion": {
   "x": {"amplitude_m": 0.02, "frequency_hz": 1.0, "sample_rate_hz": 256},
   "y": {"amplitude_m": 0.01, "frequency_hz": 1.5, "sample_rate_hz": 256},
   "z": {"amplitude_m": 0.002, "frequency_hz": 3.0, "sample_rate_hz": 256}}}}
JSON
run simulate_six_csv simulate "$six/lhpost6-sines.json" --out "$six/sines.csv"
run simulate_six_json simulate "$six/lhpost6-sines.json" --json
run simulate_six_text simulate "$six/lhpost6-sines.json"
run simulate_six_plot simulate "$six/lhpost6-sines.json" --json --out "$six/sines.parquet" \
  --plot "$six/sines-figures"
run model_six_json model --scenario "$six/lhpost6-sines.json" --json
run generate_six_target generate excitation "$six/lhpost6-sines.json" --out "$six/target.csv"
run plan_six_json plan "$six/lhpost6-sines.json" --target "$six/target.csv" --out "$six/drive.csv" \
  --iterations 2 --json
run plan_six_text plan "$six/lhpost6-sines.json" --target "$six/target.csv" --out "$six/drive2.csv" \
  --iterations 2 --per-axis-scale --plot "$six/plan-figures"
if [ -n "${PLATEN_RECORDS_DIR:-}" ]; then
  run plan_tarzana3_json plan scenarios/multi-axis/lhpost6-northridge-25.json \
    --target "$out/multi-axis_lhpost6-northridge-25.json.excitation.csv" \
    --out "$six/tarzana3-drive.csv" --iterations 2 --json
fi

# The outputs name the folder they were written to; make the listing path-independent.
grep -rl -- "$out" "$out" | while read -r f; do
  sed -i "s#$out#OUT#g" "$f"
done
echo "wrote $(find "$out" -type f | wc -l) files to $out"
