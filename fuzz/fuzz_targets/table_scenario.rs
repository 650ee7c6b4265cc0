//! The multi-axis table on arbitrary scenario bytes: parsed, validated, described (modes,
//! capacities, the linearised loop's stability and margins) and, when its run is short, run;
//! accept or reject, never panic, never hang (the loop's step budget refuses what would).
#![no_main]

use libfuzzer_sys::fuzz_target;
use platen_scenario::multi_axis::{TableRunSpec, TableScenario};

/// Runs shorter than this many samples are run too (a few milliseconds each).
const MAX_RUN_SAMPLES: usize = 400;

fuzz_target!(|data: &[u8]| {
    let dir = std::env::temp_dir().join(format!("platen-fuzz-table-{}", std::process::id()));
    let _ = std::fs::create_dir_all(&dir);
    // A short six-DOF motion and actuator forces for scenarios that name them.
    let _ = std::fs::write(
        dir.join("m.csv"),
        "t_s,x_m,z_m,pitch_rad\n0,0,0,0\n0.01,0.0001,0,0\n0.02,0.0002,0.0001,0.0001\n",
    );
    let text = String::from_utf8_lossy(data);
    let path = dir.join("s.json");
    let Ok(file) = platen_scenario::scenario::parse(&path, &text) else {
        return;
    };
    if file.table.is_none() {
        return;
    }
    if let Ok(described) = TableScenario::for_description(&path, &file) {
        let _ = described.describe();
    }
    if let Ok(scenario) = TableScenario::from_file(&path, &file) {
        let samples = match &scenario.run {
            TableRunSpec::Inverse { motion } | TableRunSpec::Loop { command: motion } => {
                motion.len()
            }
            TableRunSpec::Forward { forces, .. } => forces.len(),
        };
        if samples <= MAX_RUN_SAMPLES {
            if let Ok((run, stats)) = scenario.run_with_stats() {
                let _ = scenario.summary_with(&run, stats.as_ref(), None);
            }
        }
    }
});
