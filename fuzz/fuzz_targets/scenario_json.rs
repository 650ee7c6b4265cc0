//! The scenario parser and validator on arbitrary bytes: accept or reject, never panic.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let dir = std::env::temp_dir().join(format!("platen-fuzz-{}", std::process::id()));
    let _ = std::fs::create_dir_all(&dir);
    // A small valid record for scenarios that name `f.csv`.
    let _ = std::fs::write(dir.join("f.csv"), "t_s,force_n\n0,0\n0.5,1\n1,2\n");
    let path = dir.join("s.json");
    if std::fs::write(&path, data).is_ok() {
        let _ = platen_scenario::Scenario::load(&path);
    }
    let text = String::from_utf8_lossy(data);
    let _ = platen_scenario::scenario::parse(std::path::Path::new("s.json"), &text);
});
