//! The serial link of a board robot that messages other robots
//! (`semo_static_link.c`, `docs/link.md`): its buffers sized from the
//! mission, for the Makefile. A frame's payload is at most the longest the
//! robot can send or be sent: a `send` or `publish` (a length byte and the
//! destination, then the datagram) or a message (a datagram). A datagram
//! holds a sender's team and robot, which are the fleet's (every sender is
//! a robot of the mission, or the operator `USER`); a key, at most the
//! runtime's 63 bytes (`semo_message::key`: the keys a robot may hear
//! include shared values' and other teams' events, so the runtime's bound
//! is the one that holds for all); and a value, at most a text of the
//! longest text any robot of the fleet holds (63 bytes on Linux, the board's
//! own `SEMO_TEXT_MAX - 1`). A frame longer than the board's buffer would be
//! refused by the board and repeated by the gateway forever: the bound must
//! hold for everything the fleet can say, not only for what this robot
//! says.
//!
//! The robot also sends its status (`semo_static_status.c`), a JSON object
//! of its own names, which may be longer than anything it is sent: the
//! frames it sends are sized for the longer of the two
//! ([`send_max`]), the frames it takes only for what it may be sent.

use crate::refine::{RobotProgram, SlotSource, StateKind};

/// The longest key a datagram carries (`semo_message::key` holds 64 bytes
/// with its NUL).
const KEY_MAX: usize = 63;
/// The longest text a Linux robot sends (`SEMO_TEXT_MAX` is 64 there).
const LINUX_TEXT_MAX: usize = 63;
/// The datagram's fixed part: `"SEMO"`, the version and the kind.
const DATAGRAM_HEAD: usize = 6;
/// Reliable frames waiting behind the one in flight (`SEMO_LINK_QUEUE`):
/// a send finds room while one is acknowledged.
pub const QUEUE: usize = 2;

/// The largest frame payload on `program`'s link, `value_bytes` being its
/// own `SEMO_TEXT_MAX`.
pub fn payload_max(program: &RobotProgram, value_bytes: usize) -> usize {
    let longest = |names: &mut dyn Iterator<Item = &str>| names.map(str::len).max().unwrap_or(0);
    let user = "USER";
    let team = longest(&mut program.peers.iter().map(|(t, _)| t.as_str()).chain([user]));
    let robot = longest(&mut program.peers.iter().map(|(_, r)| r.as_str()).chain([user]));
    let text = LINUX_TEXT_MAX.max(value_bytes.saturating_sub(1));
    // A type byte, then 8 bytes (a number) or a length byte and a text.
    let value = 1 + 8.max(1 + text);
    let datagram = DATAGRAM_HEAD + (1 + team) + (1 + robot) + (1 + KEY_MAX) + value;
    // A send's destination is a team or a robot of the fleet, or USER.
    1 + team.max(robot) + datagram
}

/// An `int64_t` in decimal, sign included (`-9223372036854775808`).
const I64_DIGITS: usize = 20;

/// The longest payload the robot sends (`SEMO_LINK_SEND_MAX`): a message
/// or its status; `battery`, whether its status may say a battery level.
pub fn send_max(program: &RobotProgram, value_bytes: usize, battery: bool) -> usize {
    payload_max(program, value_bytes).max(status_max(program, battery))
}

/// Whether a robot's status may say a battery level: it reads its
/// `BATTERY` value, or (`simulated`) its scenario gives it one.
pub fn knows_battery(program: &RobotProgram, simulated_battery: bool) -> bool {
    simulated_battery
        || program.control.slots.iter().any(|s| {
            matches!(&s.source, SlotSource::Sensor { port, .. } if port == crate::refine::BATTERY_VALUE)
        })
}

/// The plans the robot runs, each with the longest name of a service it
/// runs there (JSON-escaped lengths), in the order the modes name them:
/// the status's `services`, one `Plan=Service` per plan.
fn plans(program: &RobotProgram) -> Vec<(&str, usize)> {
    let m = &program.control;
    let mut plans: Vec<(&str, usize)> = Vec::new();
    for region in m.modes.iter().flat_map(|mode| &mode.regions) {
        let service = json_len(&m.service(region.service).name);
        match plans.iter_mut().find(|(plan, _)| *plan == region.plan) {
            Some((_, longest)) => *longest = (*longest).max(service),
            None => plans.push((&region.plan, service)),
        }
    }
    plans
}

/// How many plans the status follows (`SEMO_STATUS_PLANS`), at least one.
pub fn status_plans(program: &RobotProgram) -> usize {
    plans(program).len().max(1)
}

/// The robot's statements of counted groups, each as the longest entry it
/// may put in the status's `groups` (`Name=<alive>`, JSON-escaped: its
/// longest group name or `others`, and at most as many live robots as
/// the statement has members).
fn counted_groups(program: &RobotProgram) -> Vec<usize> {
    program
        .control
        .services
        .iter()
        .flat_map(|service| &service.states)
        .filter_map(|state| match &state.kind {
            StateKind::GroupAllocate {
                members, groups, ..
            } => {
                let name = groups
                    .iter()
                    .map(|g| json_len(&g.name))
                    .chain(["others".len()])
                    .max()
                    .unwrap_or(0);
                Some(name + 1 + members.len().to_string().len())
            }
            _ => None,
        })
        .collect()
}

/// How many statements of counted groups the status follows
/// (`SEMO_STATUS_GROUPS`; 0: none, and no table on the board).
pub fn status_groups(program: &RobotProgram) -> usize {
    counted_groups(program).len()
}

/// The longest status JSON the robot writes (`semo_static_status.c`'s
/// `write_status`): its mission time, its name, its longest state, `started`
/// 0, its longest mode, the longest name of a robot it may follow when it
/// elects a leader, every plan running its longest service, its group at
/// each statement of counted groups with the most it may count, a battery
/// level when it may know one; each string as the runtime escapes it.
fn status_max(program: &RobotProgram, battery: bool) -> usize {
    let quoted = |len: usize| 2 + len;
    // `,"key":` then the value.
    let field = |key: &str, value: usize| 2 + key.len() + 2 + value;
    let m = &program.control;
    let mode = m.modes.iter().map(|mode| json_len(&mode.name)).max();
    // A leader is a robot of its team: the candidates of its `leader`
    // arms, or a team mate whose heartbeat claims the leadership.
    let leader = if m.heartbeat {
        program
            .peers
            .iter()
            .filter(|(team, _)| *team == program.team)
            .map(|(_, r)| json_len(r))
            .max()
    } else {
        None
    };
    let plans = plans(program);
    let services = plans
        .iter()
        .map(|(plan, service)| json_len(plan) + 1 + service)
        .sum::<usize>()
        + plans.len().saturating_sub(1);
    let counted = counted_groups(program);
    let groups = counted.iter().sum::<usize>() + counted.len().saturating_sub(1);
    let state = ["running", "finished", "stopped"].map(str::len);
    "{\"t\":".len()
        + I64_DIGITS
        + field("robot", quoted(json_len(&program.robot)))
        + field("event", quoted("status".len()))
        + field("state", quoted(state.into_iter().max().unwrap_or(0)))
        + field("started", quoted("0".len()))
        + field("mode", quoted(mode.unwrap_or(0)))
        + field("leader", quoted(leader.unwrap_or(0)))
        + field("services", quoted(services))
        + if counted.is_empty() {
            0
        } else {
            field("groups", quoted(groups))
        }
        + if battery {
            field("battery", quoted(I64_DIGITS))
        } else {
            0
        }
        + "}".len()
}

/// The length of `text` in a JSON string as the runtime escapes it
/// (`semo_core.c`'s `semo__json_chars`): `"` and `\` and `\n`, `\r`, `\t`
/// in two bytes, other control characters in six (`\u00XX`), the rest as
/// its UTF-8 bytes.
fn json_len(text: &str) -> usize {
    text.chars()
        .map(|c| match c {
            '"' | '\\' | '\n' | '\r' | '\t' => 2,
            c if (c as u32) < 0x20 => 6,
            c => c.len_utf8(),
        })
        .sum()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The refined programs of a mission written for the test.
    fn refined(text: &str) -> Vec<RobotProgram> {
        let catalog = crate::catalog::builtin_catalog();
        let file = crate::diag::FileId(0);
        let analysis = crate::check_source(file, text, &catalog);
        assert!(!analysis.has_errors(), "{:#?}", analysis.diagnostics);
        let input = crate::refine::RefineInput {
            mission_name: "test.mission",
            file,
            text,
            analysis: &analysis,
            catalog: &catalog,
            strategies: &[],
            strategy_names: &[],
            links: &Default::default(),
            service_graphs: &[],
        };
        let (programs, diagnostics) = crate::refine::refine(&input);
        assert!(diagnostics.is_empty(), "{diagnostics:#?}");
        programs
    }

    const SCOUTS: &str = "{\n  MasterTeam: iRobotCreate irobot\n  SlaveTeam: TIEvalbot ti, NXTLego nxt\n}\nSlaveTeam.R.S {\n  send(MasterTeam, SlaveTeam.COLOR)\n} repeat()\nSlaveTeam.M {\n  set(R, S)\n}\nSlaveTeam.main {\n  default: mode = M\n}\n";

    #[test]
    fn the_payload_holds_the_fleets_longest_names_a_full_key_and_a_linux_text() {
        let programs = refined(SCOUTS);
        let ti = programs.iter().find(|p| p.robot == "ti").unwrap();
        // 1 + "MasterTeam" (10), then the datagram: 6 + 1 + 10 + 1 + 6
        // ("irobot") + 1 + 63 + 1 + 1 + 63.
        assert_eq!(payload_max(ti, 16), 11 + 6 + 11 + 7 + 64 + 65);
        // A board text longer than Linux's counts instead.
        assert_eq!(payload_max(ti, 100), 11 + 6 + 11 + 7 + 64 + 101);
    }

    /// The bound is the length of the longest status the runtime can
    /// write, written out: the longest time, state, mode, leader and each
    /// plan's longest service, and a battery level when it may know one.
    #[test]
    fn the_status_bound_is_the_longest_status_written_out() {
        let programs = refined(SCOUTS);
        let ti = programs.iter().find(|p| p.robot == "ti").unwrap();
        let longest = r#"{"t":-9223372036854775808,"robot":"ti","event":"status","state":"finished","started":"0","mode":"M","leader":"","services":"R=S"}"#;
        assert_eq!(status_max(ti, false), longest.len());
        let battery = r#","battery":"-9223372036854775808""#;
        assert_eq!(status_max(ti, true), longest.len() + battery.len());
        // Longer than what ti is sent, it sizes what ti sends.
        assert_eq!(send_max(ti, 16, false), payload_max(ti, 16));
        assert!(!knows_battery(ti, false) && knows_battery(ti, true));

        // Two plans, each with its longest service, in the order the modes
        // name them; a leader of its own team when it elects one.
        let text = "{\n  Guards: Turtlebot3_Burger tb[2]\n  Base: iRobotCreate headquarters\n}\nGuards.Report.ToBase {\n  [[\n    leader(instance of Turtlebot3_Burger) {\n      publish(Base, Guards.Alarm)\n    }\n  ]]\n} repeat(1 SEC)\nGuards.Action.Patrolling {\n  move(\"1,1\")\n} repeat()\nGuards.Action.Rest {\n  standby()\n} repeat()\nGuards.PATROL {\n  set(Action, Patrolling)\n  set(Report, ToBase)\n}\nGuards.RESTING {\n  set(Action, Rest)\n  set(Report, OFF)\n}\nGuards.main {\n  default: mode = PATROL\n}\n";
        let programs = refined(text);
        let tb = programs.iter().find(|p| p.robot == "tb_0").unwrap();
        assert!(tb.control.heartbeat, "tb elects a leader");
        assert_eq!(status_plans(tb), 2);
        let longest = r#"{"t":-9223372036854775808,"robot":"tb_0","event":"status","state":"finished","started":"0","mode":"RESTING","leader":"tb_0","services":"Action=Patrolling,Report=ToBase"}"#;
        assert_eq!(status_max(tb, false), longest.len());
    }

    /// Each statement of counted groups adds its longest entry (its
    /// longest group name or `others`, `=`, the most it may count), the
    /// entries separated by commas, after the services.
    #[test]
    fn the_status_bound_holds_a_group_at_each_statement_of_counted_groups() {
        let text = "{ Crew: Turtlebot3_Burger tb[12] }\nCrew.Work.Search {\n  [[ group(Room1, min = 2) {\n       [[ group(Sweeper, min = 1) { move(\"1,4\") }\n          others { standby() } ]]\n     }\n     group(Hall, min = 1) { move(\"6,2\") }\n     others { standby() }\n  ]]\n} repeat(1 SEC)\nCrew.SEARCH { set(Work, Search) }\nCrew.main { default: mode = SEARCH }\n";
        let programs = refined(text);
        let tb = programs.iter().find(|p| p.robot == "tb_0").unwrap();
        assert_eq!(status_groups(tb), 2);
        let plain = r#"{"t":-9223372036854775808,"robot":"tb_0","event":"status","state":"finished","started":"0","mode":"SEARCH","leader":"tb_10","services":"Work=Search"}"#;
        let groups = r#","groups":"others=12,Sweeper=12""#;
        assert_eq!(status_max(tb, false), plain.len() + groups.len());
        // Without counted groups: no table and nothing in the bound.
        let programs = refined(SCOUTS);
        let ti = programs.iter().find(|p| p.robot == "ti").unwrap();
        assert_eq!(status_groups(ti), 0);
    }

    #[test]
    fn json_lengths_are_the_runtime_s_escapes() {
        assert_eq!(json_len("PATROL"), 6);
        assert_eq!(json_len(r#"MOVE("a\b")"#), 14);
        assert_eq!(json_len("a\nb\tc\u{1}"), 1 + 2 + 1 + 2 + 1 + 6);
        assert_eq!(json_len("é€"), 2 + 3);
    }
}
