use super::testing::*;
use super::*;
use crate::span::Span;

#[test]
fn multirate_chain_has_the_smallest_repetition_vector() {
    let g = graph(
        "chain",
        vec![
            task("A", &["o>2"]),
            task("B", &["i<3", "o>1"]),
            task("C", &["i<2"]),
        ],
        vec![channel("A.o", "B.i", 0, 1), channel("B.o", "C.i", 0, 2)],
    );
    let report = analyze(&g);
    assert!(report.diagnostics.is_empty(), "{:?}", report.diagnostics);
    assert_eq!(report.levels[0].repetition, Some(vec![3, 2, 1]));
    assert_eq!(report.levels[0].deadlock_free, Some(true));
}

#[test]
fn inconsistency_names_the_channel_and_both_ratios() {
    // A→B→D makes D fire twice per A (B produces 2); A→C→D once.
    let g = graph(
        "inconsistent",
        vec![
            task("A", &["o1>1", "o2>1"]),
            task("B", &["i<1", "o>2"]),
            task("C", &["i<1", "o>1"]),
            task("D", &["i1<1", "i2<1"]),
        ],
        vec![
            channel("A.o1", "B.i", 0, 1),
            channel("A.o2", "C.i", 0, 2),
            channel("B.o", "D.i1", 0, 3),
            channel("C.o", "D.i2", 0, 4),
        ],
    );
    let report = analyze(&g);
    assert_eq!(report.levels[0].repetition, None);
    let d = &report.diagnostics[0];
    assert_eq!(d.code, Code::InconsistentRates);
    assert!(
        d.message.contains("fire once per firing of C"),
        "{}",
        d.message
    );
    assert!(d.message.contains("fire 2 times"), "{}", d.message);
    assert_eq!(d.span, Span::new(4, 5));
}

#[test]
fn deadlock_names_the_cycle_and_the_samples_that_would_suffice() {
    let g = graph(
        "deadlock",
        vec![
            task("S", &["o>1"]),
            task("X", &["in<1", "fb<1", "o>1"]),
            task("Y", &["i<1", "back>1", "o>1"]),
            task("Z", &["i<1"]),
        ],
        vec![
            channel("S.o", "X.in", 0, 1),
            channel("X.o", "Y.i", 0, 2),
            channel("Y.back", "X.fb", 0, 3),
            channel("Y.o", "Z.i", 0, 4),
        ],
    );
    let report = analyze(&g);
    assert_eq!(report.levels[0].deadlock_free, Some(false));
    let d = &report.diagnostics[0];
    assert_eq!(d.code, Code::Deadlock);
    assert_eq!(d.span, Span::new(3, 4), "points at the feedback channel");
    assert!(d.message.contains("X → Y → X"), "{}", d.message);
    assert!(
        d.message
            .contains("1 more initial sample on channel Y.back → X.fb"),
        "{}",
        d.message
    );

    let mut fixed = g.clone();
    fixed.channels[2].initial_tokens = 1;
    assert!(analyze(&fixed).is_deadlock_free());
}

#[test]
fn multirate_cycle_needs_enough_samples_for_a_whole_iteration() {
    // A produces 3 per firing, B consumes 2: γ = (2, 3); the feedback B→A
    // (B produces 2, A consumes 3) needs 3 samples for A's first firing.
    let g = graph(
        "cycle",
        vec![task("A", &["i<3", "o>3"]), task("B", &["i<2", "o>2"])],
        vec![channel("A.o", "B.i", 0, 1), channel("B.o", "A.i", 2, 2)],
    );
    let report = analyze(&g);
    assert_eq!(report.levels[0].repetition, Some(vec![2, 3]));
    // 3 samples let A fire once and B once, then both starve: 4 are needed.
    let message = &report.diagnostics[0].message;
    assert!(message.contains("the cycle A → B → A"), "{message}");
    assert!(
        message.contains("2 more initial samples on channel B.o → A.i"),
        "{message}"
    );
}

#[test]
fn self_loops_need_a_sample_to_fire() {
    let live = graph(
        "s",
        vec![task("A", &["i<1", "o>1"])],
        vec![channel("A.o", "A.i", 1, 1)],
    );
    assert!(analyze(&live).is_deadlock_free());
    let dead = graph(
        "s",
        vec![task("A", &["i<1", "o>1"])],
        vec![channel("A.o", "A.i", 0, 1)],
    );
    assert!(!analyze(&dead).is_deadlock_free());
}

#[test]
fn loop_bodies_are_levels_with_a_boundary_firing_once() {
    let g = data_loop();
    let report = analyze(&g);
    assert!(report.diagnostics.is_empty(), "{:?}", report.diagnostics);
    assert_eq!(report.levels.len(), 2);
    assert_eq!(report.levels[0].repetition, Some(vec![1, 1, 1]));
    assert_eq!(report.levels[1].path, "data_loop/L");
    assert_eq!(
        report.levels[1].nodes,
        ["B", "C", "L (inputs)", "L (outputs)"]
    );
    assert_eq!(report.levels[1].repetition, Some(vec![1, 1, 1, 1]));
}

#[test]
fn huge_rates_are_an_overflow_diagnostic_not_a_panic() {
    let big = 1u64 << 40;
    let g = graph(
        "big",
        vec![
            task("A", &[&format!("o>{big}")]),
            task("B", &["i<1", &format!("o>{big}")]),
            task("C", &["i<1"]),
        ],
        vec![channel("A.o", "B.i", 0, 1), channel("B.o", "C.i", 0, 2)],
    );
    let report = analyze(&g);
    assert_eq!(report.diagnostics[0].code, Code::RateOverflow);
}
