//! The time-series CSV reader on arbitrary bytes: accept or reject, never panic.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let path = std::env::temp_dir().join(format!("platen-fuzz-csv-{}.csv", std::process::id()));
    if std::fs::write(&path, data).is_ok() {
        if let Ok(t) = platen_io::csv::read_table(&path, &["t_s", "force_n"], &["u_m", "v_m_s"]) {
            let time = t.column("t_s").expect("required column");
            assert!(time.windows(2).all(|w| w[1] > w[0]), "accepted a non-increasing time column");
            let _ = platen_scenario::sampling::uniform_step_s(&path, time);
        }
    }
});
