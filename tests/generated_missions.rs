//! A property guarding the whole pipeline, over random valid missions
//! (`support/missiongen.rs`, the built-in catalog): whatever `semo check`
//! accepts, `semo build` accepts for every target, and every robot it writes
//! compiles and links with gcc and clang at `-std=c11 -Wall -Wextra
//! -Wpedantic -Werror`.
//!
//! To stay within a few minutes on two cores, the runtime (the same in every
//! robot folder of a target) is compiled once per compiler and target, each
//! robot's own files are compiled at `-O0` and linked against it, and the
//! compilations run on a pool bounded by the machine's cores.
//!
//! CI runs 40 missions; `cargo test --test generated_missions -- --ignored`
//! runs 2000 (`SEMO_MISSIONS=N` to choose).

mod support;

use semo::catalog::builtin_catalog;
use std::path::PathBuf;
use support::cc::compile_all;
use support::missiongen;
use support::robots::scratch;
use support::semo_in;

const TARGETS: [&str; 2] = ["linux", "linux-sim"];

#[test]
fn generated_missions_check_build_and_compile_pedantically() {
    pipeline_holds("generated", 0..40);
}

#[test]
#[ignore = "thousands of missions: run on demand"]
fn thousands_of_generated_missions_check_build_and_compile() {
    let count = std::env::var("SEMO_MISSIONS")
        .ok()
        .and_then(|n| n.parse().ok())
        .unwrap_or(2000);
    pipeline_holds("generated-many", 1000..1000 + count);
}

#[test]
fn the_generator_is_deterministic_and_varied() {
    let catalog = builtin_catalog();
    assert_eq!(
        missiongen::mission(7, &catalog),
        missiongen::mission(7, &catalog)
    );
    let texts: Vec<String> = (0..40).map(|s| missiongen::mission(s, &catalog)).collect();
    // Every construct the generator promises appears somewhere in 40 missions.
    for construct in [
        "[[",
        "group(instance of",
        "group(capable of",
        "leader(",
        "others",
        "send(",
        "receive(",
        "publish(",
        "subscribe(",
        "def helper0",
        "helper0()",
        "loop(",
        "if(",
        "else",
        "throw",
        "repeat(",
        "OFF",
        "timeout =",
        "case (",
        "[2]",
    ] {
        assert!(
            texts.iter().any(|t| t.contains(construct)),
            "no generated mission has `{construct}`"
        );
    }
    let several_capabilities = texts.iter().any(|t| {
        t.lines()
            .any(|l| l.contains("capable of") && l.contains(','))
    });
    assert!(several_capabilities, "`capable of A, B` appears");
    let mixed_team = texts.iter().any(|t| {
        t.lines().any(|l| {
            let types: std::collections::BTreeSet<&str> = l
                .split(',')
                .filter_map(|d| d.split(':').next_back()?.split_whitespace().next())
                .collect();
            l.starts_with("  ") && l.contains(':') && types.len() > 1
        })
    });
    assert!(mixed_team, "a team mixes robot types");
}

/// Whatever `semo check` accepts builds: over missions with odd name shapes
/// (`missiongen::odd_mission`), each one check accepts without an error is
/// built for every target, which may refuse it only with a positioned
/// diagnostic of its own (a target's limits, E103), never an internal error
/// (E102, something the checker should have refused).
#[test]
fn what_check_accepts_in_odd_missions_builds_for_every_target() {
    odd_missions_build("odd", 0..60);
}

#[test]
#[ignore = "thousands of missions: run on demand"]
fn thousands_of_odd_missions_build_when_checked() {
    let count = std::env::var("SEMO_MISSIONS")
        .ok()
        .and_then(|n| n.parse().ok())
        .unwrap_or(2000);
    odd_missions_build("odd-many", 1000..1000 + count);
}

fn odd_missions_build(name: &str, seeds: std::ops::Range<u64>) {
    let catalog = builtin_catalog();
    let root = scratch(name);
    let mut accepted = 0;
    for seed in seeds.clone() {
        let text = missiongen::odd_mission(seed, &catalog);
        let dir = root.join(format!("m{seed}"));
        std::fs::create_dir_all(&dir).unwrap();
        std::fs::write(dir.join("odd.mission"), &text).unwrap();
        let (code, _) = support::check_json_in(&dir, &["odd.mission"]);
        if code != 0 {
            continue;
        }
        accepted += 1;
        // A simulation has a scenario compiled in: one with nothing in it.
        std::fs::write(dir.join("quiet.scenario.json"), r#"{"duration": 2000}"#).unwrap();
        for target in ["linux", "linux-sim", "cortex-m"] {
            let out = dir.join(target).display().to_string();
            let mut args = vec![
                "build",
                "odd.mission",
                "--target",
                target,
                "-o",
                &out,
                "--format",
                "json",
            ];
            if target.ends_with("-sim") {
                args.extend(["--scenario", "quiet.scenario.json"]);
            }
            let built = semo_in(&dir, &args);
            let diags = support::parse_json_report(&built.stdout);
            let errors: Vec<_> = diags.iter().filter(|d| d.severity == "error").collect();
            let internal = errors.iter().any(|d| d.code == "E102");
            let unplaced = errors.iter().any(|d| d.start.0 == 0 || d.file.is_empty());
            assert!(
                (built.code == 0 && errors.is_empty())
                    || (built.code == 1 && !errors.is_empty() && !internal && !unplaced),
                "seed {seed}: `semo check` accepts it, `semo build --target {target}` exits {}:\n{text}\n{}{}",
                built.code,
                support::listing(&diags),
                built.stderr
            );
        }
    }
    // The shapes are odd, not hopeless: many missions still check.
    assert!(
        accepted * 4 >= seeds.count(),
        "only {accepted} odd missions pass `semo check`"
    );
}

/// The property over the missions of `seeds`.
fn pipeline_holds(name: &str, seeds: std::ops::Range<u64>) {
    let catalog = builtin_catalog();
    let root = scratch(name);
    let mut outputs: Vec<(String, &str, PathBuf)> = Vec::new();
    for seed in seeds {
        let text = missiongen::mission(seed, &catalog);
        let dir = root.join(format!("m{seed}"));
        std::fs::create_dir_all(&dir).unwrap();
        let mission = dir.join("generated.mission");
        std::fs::write(&mission, &text).unwrap();
        let checked = semo_in(&dir, &["check", "generated.mission"]);
        assert_eq!(
            checked.code, 0,
            "seed {seed}: the generator wrote a mission `semo check` refuses:\n{text}\n{}",
            checked.stderr
        );
        for target in TARGETS {
            let out = dir.join(target);
            let built = support::robots::build_for(&mission, target, &out);
            assert_eq!(
                built.code, 0,
                "seed {seed}: `semo check` accepts it but `semo build --target {target}` refuses:\n{text}\n{}{}",
                built.stdout, built.stderr
            );
            outputs.push((format!("seed {seed}"), target, out));
        }
    }
    compile_all(&root, &outputs, &TARGETS);
}
