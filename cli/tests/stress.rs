//! `glint stress` from the command line: the small CI run (every count zero,
//! joints included, exit 0, well under a minute) and its bad flags.

mod common;

use common::{assert_input_error, glint, stdout};

#[test]
fn a_small_stress_run_counts_nothing_and_exits_zero() {
    let dir = tempfile::tempdir().unwrap();
    let o = glint(&["stress", "--grid", "8"], dir.path());
    let out = stdout(&o);
    assert_eq!(o.status.code(), Some(0), "{out}");
    let rows: Vec<&str> = out.lines().filter(|l| l.starts_with("| ")).collect();
    // The header, then 15 configurations and 3 shipped scenes at 6 scales,
    // each at two offsets.
    assert_eq!(rows.len(), 1 + 216, "{out}");
    for row in &rows[1..] {
        let counts: Vec<&str> = row.split('|').map(str::trim).skip(5).take(5).collect();
        assert_eq!(counts, ["0"; 5], "{row}");
    }
    assert!(out.contains("every count is zero"), "{out}");
    assert!(out.contains("icosahedron, inside") && out.contains("box of 6 walls"));
    assert!(out.contains("| scene bunny |") && out.contains("| scene cornell-set1 |"));
    assert_eq!(
        std::fs::read_dir(dir.path()).unwrap().count(),
        0,
        "nothing written"
    );
}

#[test]
fn bad_stress_flags_are_one_clear_error() {
    let dir = tempfile::tempdir().unwrap();
    assert_input_error(&glint(&["stress", "--grid", "1"], dir.path()), "--grid");
    assert_input_error(&glint(&["stress", "--grid", "many"], dir.path()), "--grid");
    assert_input_error(&glint(&["stress", "--joints"], dir.path()), "--joints");
}
