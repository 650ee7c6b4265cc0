//! Outputs are ordinary files: others on the lab's machine can read them. An atomic output
//! gets the mode that `File::create` gives a new file in the same folder (`0o666` less the
//! process's umask), not the temporary file's private `0600`.

#![cfg(unix)]

use std::os::unix::fs::PermissionsExt;

use platen_io::write_bytes_atomic;

#[test]
fn an_output_has_the_mode_of_any_new_file() {
    let dir = tempfile::tempdir().unwrap();
    let reference = dir.path().join("made-by-std.txt");
    std::fs::File::create(&reference).unwrap();
    let ours = dir.path().join("run.csv");
    write_bytes_atomic(&ours, b"t_s,u_m\n0,0\n").unwrap();
    let mode = |p: &std::path::Path| std::fs::metadata(p).unwrap().permissions().mode() & 0o777;
    assert_eq!(mode(&ours), mode(&reference));
    // Under the usual umask 022 that is 0644, readable by group and others; never 0600
    // unless the umask says so.
    assert_ne!(
        mode(&reference),
        0o600,
        "this test needs a umask that leaves group read"
    );
    assert_eq!(mode(&ours) & 0o044, 0o044);
    // Overwriting keeps it so.
    write_bytes_atomic(&ours, b"t_s,u_m\n0,1\n").unwrap();
    assert_eq!(mode(&ours), mode(&reference));
}
