//! The PEER NGA reader on arbitrary bytes: accept or reject, never panic.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let path = std::env::temp_dir().join(format!("platen-fuzz-peer-{}.AT2", std::process::id()));
    if std::fs::write(&path, data).is_ok() {
        if let Ok(r) = platen_io::peer::read_peer(&path) {
            assert!(r.values.iter().all(|x| x.is_finite()));
            assert!(r.dt_s > 0.0);
        }
    }
});
