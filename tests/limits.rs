//! The tools' limits (`docs/limits.md`), through the `semo` binary: an input
//! past one is refused with a positioned error at once and in bounded memory
//! (robot counts, XML nesting), an input within them costs in proportion to
//! its size (many services, many attributes), and a mission is read as a
//! mission whatever its first line looks like.
//!
//! "At once and in bounded memory" is held by running `semo` under `ulimit`
//! bounds far above what any check needs and far below what these inputs took
//! before their limits (gigabytes, minutes): past a bound the process is
//! killed, and the test sees it. "In proportion" counts the instructions
//! (valgrind's callgrind) that two sizes ten times apart add to the empty
//! input's, against a bound of twelve: a quadratic path adds a hundred
//! times more there, a linear one ten. `semo simulate` is held the same
//! way: what each doubling of a swarm's robots adds.

mod support;

use std::path::Path;
use support::{Diag, Output, parse_json_report, repo_root};

/// The address space a check may take here (`ulimit -v`), in KiB: a check of
/// any input below uses a small part of it.
const MEMORY_KIB: u64 = 1536 * 1024;
/// The CPU time a check may take here (`ulimit -t`), in seconds.
const CPU_SECONDS: u64 = 120;

/// Runs `semo ARGS` in `dir` under [`MEMORY_KIB`] and [`CPU_SECONDS`].
fn semo_bounded(dir: &Path, args: &[&str]) -> Output {
    let script =
        format!("ulimit -v {MEMORY_KIB} && ulimit -t {CPU_SECONDS} && exec \"$@\" || exit 99");
    let out = std::process::Command::new("sh")
        .arg("-c")
        .arg(script)
        .arg("sh")
        .arg(env!("CARGO_BIN_EXE_semo"))
        .args(args)
        .current_dir(dir)
        .env("NO_COLOR", "1")
        .output()
        .expect("sh runs");
    Output {
        code: out.status.code().unwrap_or(-1),
        stdout: String::from_utf8_lossy(&out.stdout).into_owned(),
        stderr: String::from_utf8_lossy(&out.stderr).into_owned(),
    }
}

/// `semo check --format json PATHS` in `dir`, bounded, parsed; the exit
/// status must be 0 or 1 (a check, not a crash).
fn check_bounded(dir: &Path, paths: &[&str]) -> (i32, Vec<Diag>) {
    let mut args = vec!["check", "--format", "json"];
    args.extend_from_slice(paths);
    let out = semo_bounded(dir, &args);
    assert!(
        out.code == 0 || out.code == 1,
        "{paths:?}: exit {} (killed past the bounds?): {}",
        out.code,
        out.stderr
    );
    (out.code, parse_json_report(&out.stdout))
}

/// The instructions `semo ARGS` runs in `dir`, counted by valgrind's
/// callgrind: a count of work that no clock, load or cache disturbs. `None`
/// when valgrind is missing (skipped with a message unless
/// `SEMO_VALGRIND_TESTS=require`, as CI sets).
fn instructions(dir: &Path, args: &[&str]) -> Option<u64> {
    instructions_and_output(dir, args).map(|(count, _)| count)
}

/// [`instructions`], with what `semo ARGS` printed and its exit status.
fn instructions_and_output(dir: &Path, args: &[&str]) -> Option<(u64, Output)> {
    let out = std::process::Command::new("valgrind")
        .args(["--tool=callgrind", "--callgrind-out-file=/dev/null"])
        .arg(env!("CARGO_BIN_EXE_semo"))
        .args(args)
        .current_dir(dir)
        .output();
    let out = match out {
        Ok(out) => out,
        Err(e) if std::env::var("SEMO_VALGRIND_TESTS").as_deref() == Ok("require") => {
            panic!("valgrind is required (SEMO_VALGRIND_TESTS=require): {e}")
        }
        Err(e) => {
            eprintln!("skipped: valgrind cannot run ({e}); install Debian's valgrind");
            return None;
        }
    };
    let stderr = String::from_utf8_lossy(&out.stderr);
    // `==123== Collected : 87021202`
    let collected = stderr
        .lines()
        .find_map(|line| line.split_once("Collected :"))
        .map(|(_, n)| n.trim().parse().expect("a count"));
    let count = collected.unwrap_or_else(|| panic!("no count from callgrind: {stderr}"));
    let output = Output {
        code: out.status.code().unwrap_or(-1),
        stdout: String::from_utf8_lossy(&out.stdout).into_owned(),
        stderr: stderr.into_owned(),
    };
    Some((count, output))
}

/// Asserts that `semo ARGS` on the input `write(dir, n)` costs in
/// proportion to `n`: what ten times the input adds to the empty input's
/// cost (`write(dir, 0)`: start-up, the built-in catalog) is at most twelve
/// times what `n` adds. A quadratic path adds a hundred times more there, a
/// linear one ten.
fn scales_linearly(what: &str, n: usize, args: &[&str], write: impl Fn(&Path, usize)) {
    let mut counts = Vec::new();
    for size in [0, n, 10 * n] {
        let dir = tempfile::tempdir().unwrap();
        write(dir.path(), size);
        let Some(count) = instructions(dir.path(), args) else {
            return;
        };
        counts.push(count);
    }
    let [empty, small, large] = counts[..] else {
        unreachable!()
    };
    let (small_adds, large_adds) = (small.saturating_sub(empty), large.saturating_sub(empty));
    let ratio = large_adds as f64 / small_adds.max(1) as f64;
    eprintln!(
        "{what}: none {empty}, {n} add {small_adds}, {} add {large_adds} instructions (x{ratio:.2})",
        10 * n
    );
    assert!(
        ratio <= 12.0,
        "{what}: {n} add {small_adds} instructions, {} add {large_adds} (x{ratio:.1})",
        10 * n
    );
}

fn copy_example(path: &str, dir: &Path) {
    let from = repo_root().join("examples").join(path);
    let name = from.file_name().unwrap();
    std::fs::copy(&from, dir.join(name)).unwrap();
}

// ---------------------------------------------------------------------------
// Robots.

/// `patrol_groups.mission` with `ev[count]` for its Ev3 robots.
fn swarm(count: &str) -> String {
    let text = std::fs::read_to_string(repo_root().join("examples/swarm/patrol_groups.mission"))
        .expect("the example");
    assert!(text.contains("ev[2]"));
    text.replace("ev[2]", &format!("ev[{count}]"))
}

/// The one-based line and column of the first `needle` in `text`.
fn line_column(text: &str, needle: &str) -> (u64, u64) {
    let at = text.find(needle).expect("the needle is in the text");
    let line = text[..at].matches('\n').count() as u64 + 1;
    let column = text[..at].rsplit('\n').next().unwrap().chars().count() as u64 + 1;
    (line, column)
}

#[test]
fn a_robot_count_past_the_limit_is_an_error_on_the_count_at_once() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    copy_example("follow/follow.mission", dir);
    // Past the limit; what took 4.6 GB and a minute; what took 51 GB;
    // more than 32 bits.
    for count in ["4097", "10000000", "2147483648", "99999999999999999999"] {
        let text = swarm(count);
        std::fs::write(dir.join("swarm.mission"), &text).unwrap();
        let (code, diags) = check_bounded(dir, &["swarm.mission"]);
        assert_eq!(code, 1);
        let e036: Vec<&Diag> = diags.iter().filter(|d| d.code == "E036").collect();
        assert_eq!(e036.len(), 1, "{count}: {}", support::listing(&diags));
        assert_eq!(e036[0].start, line_column(&text, count), "{count}");
        assert!(e036[0].message.contains("at most 4096"), "{:?}", e036[0]);
        // The other mission of the folder is checked, cleanly, alone and
        // with the folder.
        let (code, diags) = check_bounded(dir, &["follow.mission"]);
        assert_eq!((code, diags.len()), (0, 0), "{}", support::listing(&diags));
        let (_, diags) = check_bounded(dir, &["."]);
        assert!(
            diags.iter().all(|d| d.file.ends_with("swarm.mission")),
            "{}",
            support::listing(&diags)
        );
        assert!(diags.iter().any(|d| d.code == "E036"));
    }
}

#[test]
fn a_mission_past_the_robot_limit_is_an_error_on_the_declaration_that_crosses_it() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    let text = swarm("4000").replace(
        "Ev3_Robot ev[4000]",
        "Ev3_Robot ev[4000], Ev3_Robot more[90], Ev3_Robot last[9]",
    );
    std::fs::write(dir.join("swarm.mission"), &text).unwrap();
    let (code, diags) = check_bounded(dir, &["swarm.mission"]);
    assert_eq!(code, 1);
    let e036: Vec<&Diag> = diags.iter().filter(|d| d.code == "E036").collect();
    // 1 + 3 + 4000 + 90 fit; `last[9]` crosses 4096, reported once.
    assert_eq!(e036.len(), 1, "{}", support::listing(&diags));
    let (line, column) = line_column(&text, "last[9]");
    assert_eq!(e036[0].start, (line, column + "last[".len() as u64));
    assert!(e036[0].message.contains("4096"), "{:?}", e036[0]);
}

/// A mode with parameters entered with a thousand rooms from a thousand
/// catches of its `case`, with sixty-four `set`s: its copies would hold about
/// a million `set`s and catches (gigabytes). Past 65,536 the checker says
/// E048, where the copies cross it, at once and in bounded memory; below it,
/// the same mission with fewer rooms checks cleanly.
#[test]
fn modes_entered_with_too_many_lists_of_arguments_are_e048_in_bounded_memory() {
    use support::missiongen::mode_entered_with_many_rooms;
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    std::fs::write(
        dir.join("m.mission"),
        mode_entered_with_many_rooms(64, 1000),
    )
    .unwrap();
    let (code, diags) = check_bounded(dir, &["m.mission"]);
    assert_eq!(code, 1);
    let codes: Vec<&str> = diags.iter().map(|d| d.code.as_str()).collect();
    assert_eq!(codes, ["E048", "E048"], "{}", support::listing(&diags));
    assert!(diags.iter().all(|d| d.message.contains("65536")));
    // 64 sets and 1 + 99 catches, for each of 100 rooms: 16,500.
    std::fs::write(dir.join("m.mission"), mode_entered_with_many_rooms(64, 100)).unwrap();
    let (code, diags) = check_bounded(dir, &["m.mission"]);
    assert_eq!(code, 0, "{}", support::listing(&diags));
}

#[test]
fn a_swarm_of_a_thousand_robots_and_one_at_the_limit_check_cleanly() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    // The example's other robots are four: 4092 more make 4096.
    for count in ["1000", "4092"] {
        std::fs::write(dir.join("swarm.mission"), swarm(count)).unwrap();
        let (code, diags) = check_bounded(dir, &["swarm.mission"]);
        assert_eq!(code, 0, "{count}: {}", support::listing(&diags));
    }
}

#[test]
fn a_team_at_the_robot_limit_costs_little_per_statement() {
    // Every statement is checked with the robots that run it, and each of
    // these is an E033 naming the robots lacking the value: thousands of
    // statements run by thousands of robots once held their product (ids
    // per scope, every name in every message: gigabytes here).
    let tmp = tempfile::tempdir().unwrap();
    let mut text = String::from("{ T: Turtlebot3_Burger tb, Ev3_Robot ev[4095] }\n");
    let statements = 40_000;
    for i in 0..statements {
        text.push_str(&format!("T.P.S{i} {{ if (LIGHTNESS < 3) stop() }}\n"));
    }
    text.push_str("T.M { set(P, S0) }\nT.main { default: mode = M }\n");
    std::fs::write(tmp.path().join("m.mission"), &text).unwrap();
    let (code, diags) = check_bounded(tmp.path(), &["m.mission"]);
    assert_eq!(code, 1);
    let e033 = diags.iter().find(|d| d.code == "E033").expect("an E033");
    assert!(
        e033.message.contains("ev_7 and 4087 more"),
        "{}",
        e033.message
    );
}

// ---------------------------------------------------------------------------
// Simulation.

/// A scenario for [`swarm`] with `ev[count]`, naming every robot: each Ev3
/// robot's services, the light the TurtleBots read (dark at once, bright at
/// 600 ms: the team hides and comes back), an operator command to the team,
/// a robot killed and restarted, and a partition between half the team and
/// the rest. 1.2 s of mission time.
fn swarm_scenario(count: usize) -> String {
    let mut robots: Vec<String> = (0..count)
        .map(|i| format!(r#""ev_{i}": {{"services": {{"move": 300, "scatter": 200}}}}"#))
        .collect();
    robots.extend((0..3).map(|i| {
        format!(
            r#""tb_{i}": {{"sensors": [{{"at": 0, "value": "LIGHTNESS", "is": "100"}}, {{"at": 600, "value": "LIGHTNESS", "is": "700"}}]}}"#
        )
    }));
    let half: Vec<String> = (0..count / 2).map(|i| format!(r#""ev_{i}""#)).collect();
    format!(
        r#"{{"duration": 1200,
 "robots": {{{}}},
 "operator": [{{"at": 100, "to": "Guards", "value": "RC_CMD", "is": "x"}}],
 "faults": [{{"at": 200, "kill": "ev_1"}}, {{"at": 500, "restart": "ev_1"}},
            {{"partition": [["base", "tb_0", {}]], "from": 300, "until": 700}}]}}"#,
        robots.join(",\n  "),
        half.join(", ")
    )
}

/// `semo simulate` as a user runs it (reading and refining the mission,
/// reading the scenario, the run, the summary) costs in proportion to the
/// robots: from 250 to 500 to 1,000 Ev3 robots, the second doubling adds at
/// most 2.4 times what the first added (a linear cost adds twice as much,
/// a quadratic one four times). Tables of the fleet built per robot or per
/// message (a robot's scenario entry, its team's peers and heartbeat table,
/// an operator command's robots, a partition's groups, the runners of each
/// group statement, each robot's declaration) made it x3.39.
#[test]
fn simulating_twice_the_robots_costs_twice() {
    let mut counts = Vec::new();
    for count in [250, 500, 1000] {
        let tmp = tempfile::tempdir().unwrap();
        let dir = tmp.path();
        std::fs::write(dir.join("swarm.mission"), swarm(&count.to_string())).unwrap();
        std::fs::write(dir.join("swarm.scenario.json"), swarm_scenario(count)).unwrap();
        let Some((instructions, out)) =
            instructions_and_output(dir, &["simulate", "swarm.mission"])
        else {
            return;
        };
        assert_eq!(out.code, 0, "{count}: {}{}", out.stdout, out.stderr);
        // The example's other robots are four; the team hid and came back.
        let head = format!("simulated {} robot(s) for 1200 ms", count + 4);
        assert!(out.stdout.starts_with(&head), "{}", out.stdout);
        assert!(
            out.stdout
                .contains("Guards/ev_0: PATROL@0 -> HIDE@500 -> PATROL@1000"),
            "{}",
            out.stdout
        );
        counts.push(instructions);
    }
    let [small, middle, large] = counts[..] else {
        unreachable!()
    };
    let (first, second) = (middle.saturating_sub(small), large.saturating_sub(middle));
    let ratio = second as f64 / first.max(1) as f64;
    eprintln!(
        "simulate: 250 robots {small}, 500 {middle}, 1000 {large} instructions; the doublings add {first} then {second} (x{ratio:.2})"
    );
    assert!(
        ratio <= 2.4,
        "the second doubling of the robots added x{ratio:.2} the first's instructions ({first} then {second})"
    );
}

// ---------------------------------------------------------------------------
// XML nesting.

/// A root of each XML kind SeMo reads, opened and closed, with the name of
/// its file.
const XML_KINDS: &[(&str, &str, &str)] = &[
    (
        "deep.robot.xml",
        "<Catalog xmlns=\"urn:semo:catalog:1\">",
        "</Catalog>",
    ),
    ("deep.strategy.xml", "<Strategy name=\"T\">", "</Strategy>"),
    (
        "deep.taskgraph.xml",
        "<TaskGraph name=\"g\">",
        "</TaskGraph>",
    ),
    ("deep.xml", "<sdf3 type=\"sdf\" version=\"1.0\">", "</sdf3>"),
];

/// `open`, `levels` nested `<x>` elements, their ends and `close`: the root
/// at depth 1, the last `<x>` at depth `levels + 1`.
fn nested(open: &str, close: &str, levels: usize) -> String {
    [open, &"<x>".repeat(levels), &"</x>".repeat(levels), close].concat()
}

#[test]
fn xml_nested_a_million_deep_is_an_error_at_the_element_past_the_limit() {
    for &(name, open, close) in XML_KINDS {
        let tmp = tempfile::tempdir().unwrap();
        let dir = tmp.path();
        copy_example("follow/follow.mission", dir);
        let text = nested(open, close, 1_000_000);
        std::fs::write(dir.join(name), &text).unwrap();
        let (code, diags) = check_bounded(dir, &[name]);
        assert_eq!(code, 1, "{name}");
        let e097: Vec<&Diag> = diags.iter().filter(|d| d.code == "E097").collect();
        assert_eq!(e097.len(), 1, "{name}: {}", support::listing(&diags));
        // The 257th element is the 256th `<x>`: its name is at this column.
        let column = open.len() + 255 * "<x>".len() + 2;
        assert_eq!(e097[0].start, (1, column as u64), "{name}");
        // The mission beside it is checked (its catalog's error is reported
        // with it).
        let (_, diags) = check_bounded(dir, &["follow.mission"]);
        assert!(
            diags.iter().all(|d| d.file.ends_with(name)),
            "{name}: {}",
            support::listing(&diags)
        );
    }
}

#[test]
fn xml_nested_to_the_limit_is_read_without_e097() {
    for &(name, open, close) in XML_KINDS {
        let tmp = tempfile::tempdir().unwrap();
        let text = nested(open, close, 255);
        std::fs::write(tmp.path().join(name), &text).unwrap();
        let (_, diags) = check_bounded(tmp.path(), &[name]);
        assert!(
            diags.iter().all(|d| d.code != "E097"),
            "{name}: {}",
            support::listing(&diags)
        );
    }
}

#[test]
fn loops_nested_to_the_xml_limit_are_loaded_analysed_and_drawn() {
    // 126 loops: the innermost `<Port>` is 255 deep. Loading, the analyses
    // and the picture all walk the nesting.
    let dir = repo_root().join("tests/fixtures/limits");
    let name = "nested_loops.taskgraph.xml";
    let (code, diags) = check_bounded(&dir, &[name]);
    assert_eq!(code, 0, "{}", support::listing(&diags));
    for command in ["analyze", "schedule", "svg"] {
        let out = semo_bounded(&dir, &["graph", command, name]);
        assert_eq!(out.code, 0, "{command}: {}", out.stderr);
    }
}

// ---------------------------------------------------------------------------
// Costs in proportion to the input.

#[test]
fn many_services_in_one_plan_cost_in_proportion() {
    scales_linearly(
        "services in one plan",
        300,
        &["check", "--format", "json", "m.mission"],
        |dir, n| {
            let mut text = String::from("{ T: iRobotCreate a }\n");
            for i in 0..n {
                text.push_str(&format!("T.P.S{i} {{ throw e{i} }}\n"));
            }
            text.push_str("T.M { set(P, S0) }\nT.main { default: mode = M }\n");
            std::fs::write(dir.join("m.mission"), text).unwrap();
        },
    );
}

/// Functions with parameters: each call's arguments are recorded once per
/// walk and checked after every body is walked against the needs of the
/// parameter they reach, passed on from function to function: no body is
/// walked more often than without parameters, and the needs passed on are
/// gathered once per parameter.
#[test]
fn many_functions_with_parameters_cost_in_proportion() {
    scales_linearly(
        "functions with parameters",
        200,
        &["check", "--format", "json", "m.mission"],
        |dir, n| {
            let mut text = String::from(
                "{ T: TIEvalbot a }\ndef go(PLACE, WAIT) {\n  move(PLACE)\n  if (WAIT > 1) standby()\n}\n",
            );
            for i in 0..n {
                text.push_str(&format!("def f{i}(P, W) {{ go(P, W) }}\n"));
            }
            text.push_str("T.P.S {\n");
            for i in 0..n {
                text.push_str(&format!("  f{i}(room{i}, {i})\n"));
            }
            text.push_str("} repeat()\nT.M { set(P, S) }\nT.main { default: mode = M }\n");
            std::fs::write(dir.join("m.mission"), text).unwrap();
        },
    );
}

/// Parameters compared with a literal no argument gives (W020): each
/// parameter's values are resolved once, from those passed on to it, and
/// hold a bounded number of values and places to point at, so a parameter
/// passed on from many functions (`g`'s, from every `f`) costs in
/// proportion to them.
#[test]
fn many_parameters_compared_with_what_no_argument_gives_cost_in_proportion() {
    scales_linearly(
        "parameters compared with literals",
        200,
        &["check", "--format", "json", "m.mission"],
        |dir, n| {
            let mut text =
                String::from("{ T: TIEvalbot a }\ndef g(P) {\n  if (P == nowhere) standby()\n}\n");
            for i in 0..n {
                text.push_str(&format!(
                    "def f{i}(P) {{\n  g(P)\n  if (P != nowhere) standby()\n}}\n"
                ));
            }
            text.push_str("T.P.S {\n");
            for i in 0..n {
                text.push_str(&format!("  f{i}(room{})\n", i % 50));
            }
            text.push_str("} repeat()\nT.M { set(P, S) }\nT.main { default: mode = M }\n");
            std::fs::write(dir.join("m.mission"), text).unwrap();
        },
    );
}

/// Teams that all declare a variable of one name (`T.Status`) and read it:
/// whether a team has the variable is one lookup, not a walk along the list
/// of every team that declares the name (x13.7 for ten times the teams).
#[test]
fn many_teams_with_a_variable_of_one_name_cost_in_proportion() {
    scales_linearly(
        "teams sharing a variable name",
        200,
        &["check", "--format", "json", "m.mission"],
        |dir, n| {
            let n = n.max(1);
            let mut text = String::from("{\n");
            for i in 0..n {
                text.push_str(&format!("  T{i}: iRobotCreate a{i}\n"));
            }
            text.push_str("}\n");
            for i in 0..n {
                text.push_str(&format!(
                    "T{i}.P.S {{\n  send(T{}, T{i}.Status = \"x\")\n",
                    (i + 1) % n
                ));
                for k in 0..10 {
                    text.push_str(&format!("  if (Status == \"x\") throw e{k}\n"));
                }
                text.push_str(&format!(
                    "}} repeat()\nT{i}.M {{ set(P, S) }}\nT{i}.main {{ default: mode = M }}\n"
                ));
            }
            std::fs::write(dir.join("m.mission"), text).unwrap();
        },
    );
}

/// `semo check FILE` checks that file, not its folder: beside a sibling
/// mission of 3,000 teams (and no strategy file, which would be
/// cross-checked against every mission of the folder), a small mission's
/// check costs about what it costs alone (it checked the sibling too: 0.28 s
/// of CPU instead of 0.006 s, debug build).
#[test]
fn checking_one_mission_does_not_check_a_big_sibling_without_strategy_files() {
    let small = "{ T: iRobotCreate r }\nT.P.S{ stop() } repeat(1 SEC)\nT.M{ set(P, S) }\nT.main{ default: mode = M }\n";
    let mut big = String::from("{\n");
    for i in 0..3000 {
        big.push_str(&format!("  T{i}: iRobotCreate r{i}\n"));
    }
    big.push_str("}\n");
    for i in 0..3000 {
        big.push_str(&format!(
            "T{i}.P.S{{ stop() }} repeat(1 SEC)\nT{i}.M{{ set(P, S) }}\nT{i}.main{{ default: mode = M }}\n"
        ));
    }
    let mut counts = Vec::new();
    for with_sibling in [false, true] {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join("a.mission"), small).unwrap();
        if with_sibling {
            std::fs::write(dir.path().join("big.mission"), &big).unwrap();
        }
        let Some(count) = instructions(dir.path(), &["check", "a.mission"]) else {
            return;
        };
        counts.push(count);
    }
    eprintln!("alone {}, beside the big sibling {}", counts[0], counts[1]);
    assert!(
        counts[1] < counts[0] * 2,
        "alone {} instructions, beside a big sibling {}",
        counts[0],
        counts[1]
    );
}

#[test]
fn many_modes_cases_and_catches_cost_in_proportion() {
    scales_linearly(
        "modes, cases and catches",
        200,
        &["check", "--format", "json", "m.mission"],
        |dir, n| {
            let mut text = String::from("{ T: iRobotCreate a }\nT.P.S { throw e }\n");
            for i in 0..n {
                text.push_str(&format!("T.M{i} {{ set(P, S) }}\n"));
            }
            text.push_str("T.main {\n");
            for i in 0..n {
                text.push_str(&format!(
                    "  case (M{i}): catch (e): mode = M{}\n",
                    (i + 1) % n
                ));
            }
            text.push_str("  default: mode = M0\n}\n");
            std::fs::write(dir.join("m.mission"), text).unwrap();
        },
    );
}

#[test]
fn many_attributes_on_one_element_cost_in_proportion() {
    scales_linearly(
        "attributes on one element",
        2_000,
        &["check", "--format", "json", "many.robot.xml"],
        |dir, n| {
            let attributes: String = (0..n).map(|i| format!(" a{i}=\"v\"")).collect();
            let text = format!("<Catalog xmlns=\"urn:semo:catalog:1\"{attributes}/>");
            std::fs::write(dir.join("many.robot.xml"), text).unwrap();
        },
    );
    scales_linearly(
        "attributes on one SDF3 element",
        2_000,
        &["graph", "analyze", "--format", "json", "many.xml"],
        |dir, n| {
            let attributes: String = (0..n).map(|i| format!(" a{i}=\"v\"")).collect();
            let text = std::fs::read_to_string(support::sdf3().join("h263decoder.xml"))
                .expect("an SDF3 graph")
                .replacen("<sdf3 ", &format!("<sdf3{attributes} "), 1);
            std::fs::write(dir.join("many.xml"), text).unwrap();
        },
    );
}

// ---------------------------------------------------------------------------
// A mission's first line.

#[test]
fn a_mission_whose_first_line_starts_with_a_bracket_is_checked_as_a_mission() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    for text in [
        "[[ group(instance of Ev3_Robot) { stop() } ]]\n{ T: Ev3_Robot a }\n",
        "[lints]\n{ T: Ev3_Robot a }\n",
        "# a comment\n[T]\nT.main { default: mode = M }\n",
    ] {
        std::fs::write(dir.join("m.mission"), text).unwrap();
        let out = semo_bounded(dir, &["check", "--format", "json", "m.mission"]);
        assert_eq!(out.code, 1, "{text}: {}", out.stderr);
        let diags = parse_json_report(&out.stdout);
        assert!(
            diags.iter().any(|d| d.code == "E003"),
            "{text}: {}",
            support::listing(&diags)
        );
    }
}

#[test]
fn check_prints_its_json_document_even_when_it_refuses_a_file() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    // TOML named as a mission, a task graph named as a mission, a path
    // that does not exist.
    std::fs::write(dir.join("toml.mission"), "[project]\nname = \"x\"\n").unwrap();
    std::fs::copy(
        repo_root().join("examples/taskgraphs/kmeans.taskgraph.xml"),
        dir.join("graph.mission"),
    )
    .unwrap();
    for path in ["toml.mission", "graph.mission", "missing.mission"] {
        let out = semo_bounded(dir, &["check", "--format", "json", path]);
        assert_eq!(out.code, 2, "{path}");
        let document: serde_json::Value = serde_json::from_str(&out.stdout)
            .unwrap_or_else(|e| panic!("{path}: not one JSON document ({e}): {}", out.stdout));
        assert_eq!(document["command"], "check");
        let diagnostics = document["diagnostics"].as_array().unwrap();
        assert_eq!(diagnostics.len(), 1, "{document}");
        assert_eq!(diagnostics[0]["code"], serde_json::Value::Null);
        assert_eq!(diagnostics[0]["severity"], "error");
        assert_eq!(diagnostics[0]["file"], path);
        // The one line for people is on standard error, as without JSON.
        assert_eq!(out.stderr.lines().count(), 1, "{}", out.stderr);
    }
    // A broken project file is the project file its name says: E110.
    std::fs::write(dir.join("semo.toml"), "[lints\n").unwrap();
    let (code, diags) = check_bounded(dir, &["semo.toml"]);
    assert_eq!(code, 1);
    assert!(
        diags.iter().any(|d| d.code == "E110"),
        "{}",
        support::listing(&diags)
    );
}
