//! The real binary's exit statuses: 0 on success, 1 for a value out of range, 2 for bad syntax.

use kapitza_test_support::binary::Binary;

const KAPITZA: Binary = Binary(env!("CARGO_BIN_EXE_kapitza"));

fn kapitza(args: &[&str]) -> std::process::Output {
    KAPITZA.run(args)
}

#[test]
fn statuses() {
    assert_eq!(
        kapitza(&["predict", "--r", "1.75", "--angle", "90"])
            .status
            .code(),
        Some(0)
    );
    let bad = kapitza(&["predict", "--r", "-2", "--angle", "90"]);
    assert_eq!(bad.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&bad.stderr).contains("--r -2 is out of range"));
    assert_eq!(
        kapitza(&["predict", "--angle", "90"]).status.code(),
        Some(2)
    );
    assert_eq!(kapitza(&["frobnicate"]).status.code(), Some(2));
}
