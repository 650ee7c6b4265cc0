//! Build script of the root package: `--cfg platen_records` when `PLATEN_RECORDS_DIR` is set.
//!
//! The tests that need the real PEER NGA records (not shipped) carry
//! `#[cfg_attr(not(platen_records), ignore = "…")]`, so without the records `cargo test`'s own
//! summary counts them as ignored instead of passing them. `.ci/run` sets the variable.
//! Only this package is rebuilt when the variable changes.

fn main() {
    println!("cargo::rerun-if-changed=build.rs");
    println!("cargo::rerun-if-env-changed=PLATEN_RECORDS_DIR");
    println!("cargo::rustc-check-cfg=cfg(platen_records)");
    if std::env::var_os("PLATEN_RECORDS_DIR").is_some_and(|d| !d.is_empty()) {
        println!("cargo::rustc-cfg=platen_records");
    }
}
