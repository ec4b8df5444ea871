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

use crate::refine::RobotProgram;

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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_payload_holds_the_fleets_longest_names_a_full_key_and_a_linux_text() {
        let text = "{\n  MasterTeam: iRobotCreate irobot\n  SlaveTeam: TIEvalbot ti, NXTLego nxt\n}\nSlaveTeam.R.S {\n  send(MasterTeam, SlaveTeam.COLOR)\n} repeat()\nSlaveTeam.M {\n  set(R, S)\n}\nSlaveTeam.main {\n  default: mode = M\n}\n";
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
        let ti = programs.iter().find(|p| p.robot == "ti").unwrap();
        // 1 + "MasterTeam" (10), then the datagram: 6 + 1 + 10 + 1 + 6
        // ("irobot") + 1 + 63 + 1 + 1 + 63.
        assert_eq!(payload_max(ti, 16), 11 + 6 + 11 + 7 + 64 + 65);
        // A board text longer than Linux's counts instead.
        assert_eq!(payload_max(ti, 100), 11 + 6 + 11 + 7 + 64 + 101);
    }
}
