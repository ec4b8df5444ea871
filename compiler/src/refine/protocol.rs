//! The protocol the robots of a mission speak to each other, written once
//! for both back ends: the generated C (`codegen`) and the simulator (`sim`)
//! read these, so a heartbeat, a term or an election's timing means the same
//! in both. Users read it in `docs/groups.md`.

use super::RobotProgram;

/// The key of the heartbeats a team's robots publish for leader elections.
pub fn alive_key(program: &RobotProgram) -> String {
    format!("{}.__alive", program.team)
}

/// The key of the announcements a team's robots send when they reach a
/// group statement they synchronize at (`GroupSync`).
pub fn sync_key(program: &RobotProgram) -> String {
    format!("{}.__sync", program.team)
}

/// How long a robot that must first hear its team (a restarted robot, or
/// every robot of a `highest_battery` election at start) listens before an
/// election: one heartbeat period and half of one more, so that the
/// heartbeat each robot sends once per period has arrived even when its
/// sender's firing was a little late. The simulator uses the same.
pub fn listen_ms(heartbeat_ms: i64) -> i64 {
    heartbeat_ms + heartbeat_ms / 2
}

/// When a peer is lost (`docs/groups.md`, "Takeover"): a robot counts a
/// peer alive while it has heard the peer's heartbeat within this long, and
/// lost once it has been silent for longer, for every rule that asks
/// (elections, groups, group syncs, the owner of shared values, the live
/// monitor). Two heartbeat periods: one lost heartbeat is tolerated, and
/// as elections are also decided at each heartbeat, a dead leader is
/// replaced at the latest at the third heartbeat after its last one. The
/// simulator uses the same.
pub fn lost_after_ms(heartbeat_ms: i64) -> i64 {
    2 * heartbeat_ms
}

/// A leader's lease (`docs/groups.md`, "Fencing"): a robot the election
/// would choose leads only while it has heard a strict majority of the
/// candidates, itself included, within the last one and a half heartbeat
/// periods. Strictly less than [`lost_after_ms`], by half a period: with
/// elections decided at each heartbeat, a leader cut off from the majority
/// steps down at its heartbeat after its lease lapsed, no later than the
/// others count it lost, when their heartbeats are in phase (robots started
/// together) and messages take less than half a period. The simulator uses
/// the same.
pub fn lease_ms(heartbeat_ms: i64) -> i64 {
    lost_after_ms(heartbeat_ms) - heartbeat_ms / 2
}

/// The largest term (`docs/groups.md`, "Terms"): a heartbeat saying more
/// says this, and a robot that knows it begins to lead under it again, so
/// that a rogue heartbeat cannot overflow the count (`int64_t` in the C,
/// on every target).
pub const TERM_MAX: i64 = 1_000_000_000_000_000;

/// The term a robot begins to lead under: one past the highest it knows.
pub fn next_term(highest: i64) -> i64 {
    (highest + 1).min(TERM_MAX)
}

/// The term a heartbeat says (`heard_alive` in the C): its leading digits,
/// at most [`TERM_MAX`]; none is 0.
pub fn parse_term(word: &str) -> i64 {
    let digits = word.bytes().take_while(u8::is_ascii_digit);
    digits.fold(0i64, |term, d| {
        (term * 10 + i64::from(d - b'0')).min(TERM_MAX)
    })
}

/// The `heard` field of the `fenced` event: "2 of 5".
pub fn fenced_heard(heard: usize, candidates: usize) -> String {
    format!("{heard} of {candidates}")
}

/// The `reason` of the `drop` event of a message dropped because it arrived
/// before its robot became the leader of the `leader(...)` arm whose block
/// receives it (`drop_unled`). The simulator uses the same.
pub const UNLED_REASON: &str = "arrived before it led";

/// Characters of a `graph_fire` trace's `read` or `wrote` field, at most:
/// tokens beyond are cut, by the C and the simulator alike.
pub const GRAPH_TEXT_MAX: u64 = 4096;
