//! One fixture per diagnostic code, checked through `semo check --format json`.
//!
//! A fixture is `tests/fixtures/diagnostics/<CODE>_<what>.mission`, or a folder
//! `<CODE>_<what>/` (a mission with its own `*.robot.xml` or `*.strategy.xml`,
//! or a task graph). Its expected
//! diagnostics are the insta snapshot `tests/snapshots/diagnostics__<name>.snap`;
//! besides, the fixture must produce at least one diagnostic with its code.

mod support;

use semo::diag::Code;
use std::path::Path;

fn fixture_code(path: &Path) -> String {
    let name = path.file_name().unwrap().to_str().unwrap();
    name.split('_').next().unwrap().to_string()
}

#[test]
fn every_fixture_produces_its_code() {
    insta::glob!("fixtures/diagnostics/*", |path| {
        let dir = path.parent().unwrap();
        let name = path.file_name().unwrap().to_str().unwrap();
        let (_, diags) = support::check_json_in(dir, &[name]);
        let code = fixture_code(path);
        assert!(
            diags.iter().any(|d| d.code == code),
            "fixture {name} should report {code}, got:\n{}",
            support::listing(&diags)
        );
        insta::assert_snapshot!(support::listing(&diags));
    });
}

#[test]
fn every_code_has_a_fixture() {
    // Code-generation codes have their fixtures in `fixtures/build`, checked
    // through `semo build` by the build tests.
    let codes: Vec<String> = ["tests/fixtures/diagnostics", "tests/fixtures/build"]
        .iter()
        .flat_map(|dir| std::fs::read_dir(support::repo_root().join(dir)).unwrap())
        .map(|e| fixture_code(&e.unwrap().path()))
        .collect();
    // W112 needs more directory entries than a fixture should hold: it is
    // made and checked by tests/project.rs
    // (`without_a_project_file_the_search_beside_a_mission_is_bounded`).
    // `semo verify`'s codes have their fixtures in `fixtures/verify`,
    // checked through `semo verify` by tests/verify.rs.
    // E048 needs copies of modes past 65,536 `set`s and catches: it is made
    // and checked by tests/limits.rs
    // (`modes_entered_with_too_many_lists_of_arguments_are_e048_in_bounded_memory`).
    let made_by_tests = [
        "W112", "E048", "V001", "V002", "V003", "V004", "V005", "V006",
    ];
    let missing: Vec<&str> = Code::ALL
        .iter()
        .map(|c| c.as_str())
        .filter(|c| !made_by_tests.contains(c))
        .filter(|c| !codes.iter().any(|f| f == c))
        .collect();
    assert!(missing.is_empty(), "codes without a fixture: {missing:?}");
}
