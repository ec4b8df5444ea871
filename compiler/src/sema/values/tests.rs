//! The timing facts (W022, W023, W024) on small missions: each reported
//! where it holds, and each condition it rests on shown to matter.

use crate::catalog::builtin_catalog;
use crate::diag::{Code, Diagnostic, FileId};

/// The diagnostics of `text` (which must check without errors) that have
/// one of `codes`.
pub(super) fn diagnostics_with(text: &str, codes: &[Code]) -> Vec<Diagnostic> {
    let analysis = crate::check_source(FileId(0), text, &builtin_catalog());
    assert!(!analysis.has_errors(), "{:#?}", analysis.diagnostics);
    analysis
        .diagnostics
        .iter()
        .filter(|d| codes.contains(&d.code))
        .cloned()
        .collect()
}

/// The W022-W024 findings of `text` (which must check without errors), as
/// (code, the text at the finding, the lines of its related places).
fn findings(text: &str) -> Vec<(Code, String, Vec<usize>)> {
    let codes = [
        Code::ReadBeforeSent,
        Code::ForwardedOnce,
        Code::ReceiveNeverFed,
    ];
    diagnostics_with(text, &codes)
        .iter()
        .map(|d| {
            let line = |offset: usize| text[..offset].matches('\n').count() + 1;
            let related = d.related.iter().map(|r| line(r.span.start)).collect();
            (d.code, text[d.span.range()].to_string(), related)
        })
        .collect()
}

/// The line of the first `needle` in `text`.
fn line_of(text: &str, needle: &str) -> usize {
    let at = text.find(needle).expect("the needle is in the text");
    text[..at].matches('\n').count() + 1
}

fn codes(text: &str) -> Vec<Code> {
    findings(text)
        .into_iter()
        .map(|(code, _, _)| code)
        .collect()
}

// ----- W022: read before any robot can have sent it -----

/// Base decides once, at the start, on what the scouts publish; the scouts
/// publish in `scout_modes` (their default mode is `GO`, entered at the
/// start, which runs `Move`).
fn decide(decide: &str, repeat: &str, scout_sets: &str, base_main: &str) -> String {
    format!(
        "{{\n  Base: iRobotCreate base\n  Scouts: TIEvalbot ti\n}}\n\
         Base.Think.Decide{{\n{decide}\n}}{repeat}\n\
         Base.Think.Rest{{ standby() }} repeat()\n\
         Base.DECIDE{{ set(Think, Decide) }}\nBase.DONE{{ set(Think, Rest) }}\n\
         Base.main{{\n{base_main}\n  default: mode = DECIDE\n}}\n\
         Scouts.Act.Move{{ move(\"5,5\") throw there }}\n\
         Scouts.Act.Tell{{ publish(Base, Scouts.FOUND = 1) }} repeat(1 SEC)\n\
         Scouts.GO{{ {scout_sets} }}\nScouts.TELL{{ set(Act, Tell) }}\n\
         Scouts.main{{\n  case (GO):\n    catch (there): mode = TELL\n  default: mode = GO\n}}\n"
    )
}

const SUBSCRIBE_AND_TEST: &str =
    "  subscribe(Scouts, Scouts.FOUND)\n  if (Scouts.FOUND == 1) throw done";
const DONE_CASE: &str = "  case (DECIDE):\n    catch (done): mode = DONE";

#[test]
fn a_value_read_at_the_start_that_is_only_sent_later() {
    let text = decide(SUBSCRIBE_AND_TEST, "", "set(Act, Move)", DONE_CASE);
    let found = findings(&text);
    assert_eq!(found.len(), 1, "{found:?}");
    let (code, at, related) = &found[0];
    assert_eq!((*code, at.as_str()), (Code::ReadBeforeSent, "Scouts.FOUND"));
    // The publish of Scouts.FOUND, in mode TELL.
    assert_eq!(related, &[line_of(&text, "publish(Base")]);
}

#[test]
fn a_value_read_at_the_start_in_a_branch_or_sent_on_is_read_there_too() {
    let read_in_branch =
        "  subscribe(Scouts, Scouts.FOUND)\n  if (true) { send(USER, Scouts.FOUND) }";
    let text = decide(read_in_branch, "", "set(Act, Move)", "");
    assert_eq!(codes(&text), [Code::ReadBeforeSent]);
}

#[test]
fn a_value_that_may_be_sent_at_the_start_is_not_reported() {
    // The scouts publish in their default mode: with no latency, the
    // publication may come in the first instant.
    let text = decide(
        SUBSCRIBE_AND_TEST,
        "",
        "set(Act, Move) set(Report, Tell2)",
        DONE_CASE,
    )
    .replace(
        "Scouts.GO{",
        "Scouts.Report.Tell2{ publish(Base, Scouts.FOUND = 2) }\nScouts.GO{",
    );
    assert!(codes(&text).is_empty(), "{:?}", findings(&text));
}

#[test]
fn a_value_read_again_later_is_not_reported() {
    // With `repeat`, the read comes again after the value may have come.
    let text = decide(
        SUBSCRIBE_AND_TEST,
        " repeat(1 SEC)",
        "set(Act, Move)",
        DONE_CASE,
    );
    assert!(codes(&text).is_empty());
    // After a call, the read is no longer at the first instant.
    let after_call = format!("  standby()\n{SUBSCRIBE_AND_TEST}");
    let text = decide(&after_call, "", "set(Act, Move)", DONE_CASE);
    assert!(codes(&text).is_empty());
    // Inside a loop, the condition is read at every iteration.
    let in_loop =
        "  loop(1 SEC) { subscribe(Scouts, Scouts.FOUND)\n if (Scouts.FOUND == 1) throw done }";
    let text = decide(in_loop, "", "set(Act, Move)", DONE_CASE);
    assert!(codes(&text).is_empty());
}

#[test]
fn a_start_mode_entered_again_starts_the_service_again() {
    let back = "  case (DECIDE):\n    catch (done): mode = DONE\n  case (DONE):\n    catch (again): mode = DECIDE";
    let text = decide(SUBSCRIBE_AND_TEST, "", "set(Act, Move)", back).replace(
        "Base.Think.Rest{ standby() }",
        "Base.Think.Rest{ standby() throw again }",
    );
    assert!(codes(&text).is_empty(), "{:?}", findings(&text));
    // A catch of an event nobody throws there leads nowhere (W009).
    let text = decide(SUBSCRIBE_AND_TEST, "", "set(Act, Move)", back);
    assert_eq!(codes(&text), [Code::ReadBeforeSent]);
}

#[test]
fn a_value_the_reading_team_sets_or_the_operator_sends_is_not_reported() {
    let sets_it = format!("{SUBSCRIBE_AND_TEST}\n  send(USER, Scouts.FOUND = 0)");
    let text = decide(&sets_it, "", "set(Act, Move)", DONE_CASE);
    assert!(codes(&text).is_empty());
    let operator = "Base.Think.Rest{ receive(USER, Scouts.FOUND) } repeat()";
    let text = decide(SUBSCRIBE_AND_TEST, "", "set(Act, Move)", DONE_CASE)
        .replace("Base.Think.Rest{ standby() } repeat()", operator);
    assert!(codes(&text).is_empty(), "{:?}", findings(&text));
}

#[test]
fn a_reading_of_the_robots_own_is_not_reported() {
    let own = "  if (Base.LOCATION == \"0,0\") throw done";
    let text = decide(own, "", "set(Act, Move)", DONE_CASE);
    assert!(codes(&text).is_empty());
}

// ----- W023: sent on once while it keeps coming -----

/// The leader forwards the operator's command to the workers with
/// `forward` (a service repeated by `forward_repeat`), while its plan
/// Listen takes commands with `listen` (repeated by `listen_repeat`).
fn relay(
    forward: &str,
    forward_repeat: &str,
    listen: &str,
    listen_repeat: &str,
    listen_set: &str,
) -> String {
    format!(
        "{{\n  Lead: iRobotCreate lead\n  Work: TIEvalbot ti\n}}\n\
         Lead.Listen.Take{{\n{listen}\n}}{listen_repeat}\n\
         Lead.Report.Forward{{\n{forward}\n}}{forward_repeat}\n\
         Lead.RELAY{{ {listen_set} set(Report, Forward) }}\n\
         Lead.main{{ default: mode = RELAY }}\n\
         Work.Act.Obey{{\n  receive(Lead, USER.RC_CMD)\n  process(USER.RC_CMD)\n}} repeat()\n\
         Work.OBEY{{ set(Act, Obey) }}\nWork.main{{ default: mode = OBEY }}\n"
    )
}

const TAKE: &str = "  receive(USER, USER.RC_CMD)";
const EVERY_2S: &str = " repeat(2 SEC)";
const FORWARD_ONCE: &str = "  send(Work, USER.RC_CMD)";
const LISTEN: &str = "set(Listen, Take)";

#[test]
fn a_received_value_sent_on_once_while_another_plan_keeps_receiving_it() {
    let text = relay(FORWARD_ONCE, "", TAKE, EVERY_2S, LISTEN);
    let found = findings(&text);
    assert_eq!(found.len(), 1, "{found:?}");
    let (code, at, related) = &found[0];
    assert_eq!((*code, at.as_str()), (Code::ForwardedOnce, "USER.RC_CMD"));
    assert_eq!(related, &[line_of(&text, TAKE)], "the receive of Take");
}

#[test]
fn a_value_sent_on_again_is_not_reported() {
    let text = relay(FORWARD_ONCE, EVERY_2S, TAKE, EVERY_2S, LISTEN);
    assert!(codes(&text).is_empty());
    // In a loop, the send runs again.
    let text = relay(
        "  loop(1 SEC) { send(Work, USER.RC_CMD) }",
        "",
        TAKE,
        EVERY_2S,
        LISTEN,
    );
    assert!(codes(&text).is_empty());
    // The same service sends it on again, after a receive.
    let twice = format!("{FORWARD_ONCE}\n{TAKE}\n{FORWARD_ONCE}");
    let text = relay(&twice, "", TAKE, EVERY_2S, LISTEN);
    assert!(codes(&text).is_empty(), "{:?}", findings(&text));
    // The listening plan sends it on itself.
    let listen = format!("{TAKE}\n{FORWARD_ONCE}");
    let text = relay(FORWARD_ONCE, "", &listen, EVERY_2S, LISTEN);
    assert!(codes(&text).is_empty());
}

#[test]
fn a_value_not_received_again_in_the_mode_is_not_reported() {
    // Taken once only.
    let text = relay(FORWARD_ONCE, "", TAKE, "", LISTEN);
    assert!(codes(&text).is_empty());
    // Taken while a condition holds: maybe once only.
    let text = relay(FORWARD_ONCE, "", TAKE, " repeat(BATTERY > 20)", LISTEN);
    assert!(codes(&text).is_empty());
    // Taken for a while only.
    let text = relay(
        FORWARD_ONCE,
        "",
        TAKE,
        EVERY_2S,
        "set(Listen, Take, timeout = 5 SEC)",
    );
    assert!(codes(&text).is_empty());
    // Not taken in the mode at all.
    let text = relay(FORWARD_ONCE, "", TAKE, EVERY_2S, "set(Listen, OFF)");
    assert!(!codes(&text).contains(&Code::ForwardedOnce));
}

#[test]
fn the_robots_own_values_sent_once_are_not_reported() {
    let text = relay("  send(Work, Lead.LOCATION)", "", TAKE, EVERY_2S, LISTEN).replace(
        "receive(Lead, USER.RC_CMD)\n  process(USER.RC_CMD)",
        "receive(Lead, Lead.LOCATION)\n  process(USER.RC_CMD)",
    );
    assert!(codes(&text).is_empty(), "{:?}", findings(&text));
}

// ----- W024: a receive no robot can feed -----

/// Team Base receives (or subscribes to, per `kind`) Scouts.COLOR; the
/// scouts send it in `sending`, a service their modes run per `modes`.
fn fed(receive: &str, send: &str, scout_modes: &str) -> String {
    format!(
        "{{\n  Base: iRobotCreate base\n  Scouts: TIEvalbot ti\n}}\n\
         Base.Listen.Wait{{ {receive} }} repeat()\n\
         Base.LISTEN{{ set(Listen, Wait) }}\nBase.main{{ default: mode = LISTEN }}\n\
         Scouts.Act.Go{{ move(\"1,1\") throw arrived }}\n\
         Scouts.Act.Report{{ {send} }} repeat(1 SEC)\n\
         {scout_modes}\n"
    )
}

const RECEIVE_COLOR: &str = "receive(Scouts, Scouts.COLOR)";
const SEND_COLOR: &str = "send(Base, Scouts.COLOR)";
const REPORT_REACHED: &str = "Scouts.GO{ set(Act, Go) }\nScouts.REPORT{ set(Act, Report) }\n\
     Scouts.main{\n  case (GO):\n    catch (arrived): mode = REPORT\n  default: mode = GO\n}";

#[test]
fn a_receive_fed_by_a_service_that_runs_later_is_not_reported() {
    let text = fed(RECEIVE_COLOR, SEND_COLOR, REPORT_REACHED);
    assert!(codes(&text).is_empty(), "{:?}", findings(&text));
}

#[test]
fn a_receive_whose_sends_never_run() {
    // REPORT is caught from GO on an event GO never throws.
    let never = REPORT_REACHED.replace("catch (arrived)", "catch (lost)");
    let text = fed(RECEIVE_COLOR, SEND_COLOR, &never);
    let found = findings(&text);
    assert_eq!(found.len(), 1, "{found:?}");
    assert_eq!(
        (found[0].0, found[0].1.as_str()),
        (Code::ReceiveNeverFed, "Scouts.COLOR")
    );
    assert_eq!(found[0].2, [line_of(&text, SEND_COLOR)], "the send");
    // A service no mode sets (W003): the same.
    let unset = "Scouts.GO{ set(Act, Go) }\nScouts.main{ default: mode = GO }";
    let text = fed(
        "subscribe(Scouts, Scouts.COLOR)",
        "publish(Base, Scouts.COLOR)",
        unset,
    );
    assert_eq!(codes(&text), [Code::ReceiveNeverFed]);
}

#[test]
fn a_receive_that_never_runs_is_not_reported() {
    let unset = "Scouts.GO{ set(Act, Go) }\nScouts.main{ default: mode = GO }";
    let text = fed(RECEIVE_COLOR, SEND_COLOR, unset).replace(
        "Base.LISTEN{ set(Listen, Wait) }",
        "Base.LISTEN{ set(Listen, OFF) }",
    );
    assert!(!codes(&text).contains(&Code::ReceiveNeverFed));
}

/// A team that sends to itself and receives what it sent.
fn talking_to_itself(robots: &str, send_where: &str) -> String {
    format!(
        "{{\n  Solo: {robots}\n}}\n\
         Solo.Report.Tell{{ {send_where} }} repeat(1 SEC)\n\
         Solo.Listen.Hear{{ receive(Solo, Solo.X) }} repeat()\n\
         Solo.ON{{ set(Report, Tell) set(Listen, Hear) }}\nSolo.main{{ default: mode = ON }}\n"
    )
}

#[test]
fn a_robot_does_not_receive_its_own_messages() {
    let text = talking_to_itself("iRobotCreate r", "send(Solo, Solo.X = 1)");
    let found = findings(&text);
    assert_eq!(found.len(), 1, "{found:?}");
    assert_eq!(
        (found[0].0, found[0].1.as_str()),
        (Code::ReceiveNeverFed, "Solo.X")
    );
    // Two robots hear each other.
    let text = talking_to_itself("iRobotCreate r, iRobotCreate q", "send(Solo, Solo.X = 1)");
    assert!(codes(&text).is_empty());
    let text = talking_to_itself("iRobotCreate r[2]", "send(Solo, Solo.X = 1)");
    assert!(codes(&text).is_empty());
}

#[test]
fn a_robot_sees_its_own_publications() {
    let text = talking_to_itself("iRobotCreate r", "publish(Solo, Solo.X = 1)")
        .replace("receive(Solo, Solo.X)", "subscribe(Solo, Solo.X) standby()");
    assert!(codes(&text).is_empty(), "{:?}", findings(&text));
}

#[test]
fn a_receive_in_a_function_is_reported_only_when_no_caller_is_fed() {
    // Solo's robot sends Solo.X to its own team (itself: nobody) and to
    // Pair; `hear` receives it in both teams.
    let text = "{\n  Solo: iRobotCreate r\n  Pair: iRobotCreate p, iRobotCreate q\n}\n\
         def hear { receive(Solo, Solo.X) }\n\
         Solo.Report.Tell{ send(Solo, Solo.X = 1) send(Pair, Solo.X = 1) } repeat(1 SEC)\n\
         Solo.Listen.Hear{ hear() } repeat()\n\
         Solo.ON{ set(Report, Tell) set(Listen, Hear) }\nSolo.main{ default: mode = ON }\n\
         Pair.Listen.Hear{ hear() } repeat()\n\
         Pair.ON{ set(Listen, Hear) }\nPair.main{ default: mode = ON }\n";
    assert!(codes(text).is_empty(), "{:?}", findings(text));
    // Without Pair's caller, Solo's robot alone waits for itself.
    let alone = text.replace(
        "Pair.Listen.Hear{ hear() }",
        "Pair.Listen.Hear{ standby() }",
    );
    assert_eq!(codes(&alone), [Code::ReceiveNeverFed]);
}

#[test]
fn a_publication_may_feed_a_receive() {
    // The send never runs, but a robot that subscribes to nothing takes a
    // publication of the value in its `receive` (found by
    // tests/value_flow.rs on a random mission).
    let never = REPORT_REACHED.replace("catch (arrived)", "catch (lost)");
    let text = fed(RECEIVE_COLOR, SEND_COLOR, &never).replace(
        "Scouts.Act.Go{ move(\"1,1\") throw arrived }",
        "Scouts.Act.Go{ move(\"1,1\") publish(Base, Scouts.COLOR) throw arrived }",
    );
    assert!(codes(&text).is_empty(), "{:?}", findings(&text));
}
