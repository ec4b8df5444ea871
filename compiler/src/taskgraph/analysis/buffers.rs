//! Buffer bounds: how many samples each channel holds at most while a
//! schedule runs, and warnings for channels whose declared capacity is
//! smaller.

use super::level::Level;
use crate::diag::{Code, Diagnostic};

/// For each edge of `level`, the most samples it holds while the firings
/// `firings` run in order, counting its initial samples. A firing takes its
/// input samples before it produces (a firing's own inputs and outputs do not
/// coexist, except on a self-loop). Firings of unknown nodes are skipped, and
/// a firing short of samples takes what there is.
pub fn buffer_bounds(level: &Level<'_>, firings: &[usize]) -> Vec<u64> {
    let mut tokens: Vec<u64> = level.edges.iter().map(|e| e.initial_tokens).collect();
    let mut most = tokens.clone();
    let (inputs, outputs) = level.adjacency();
    let (inputs, outputs) = (inputs.slices(), outputs.slices());
    for &v in firings {
        let (Some(&ins), Some(&outs)) = (inputs.get(v), outputs.get(v)) else {
            continue;
        };
        for &i in ins {
            tokens[i] = tokens[i].saturating_sub(level.edges[i].consume);
        }
        for &i in outs {
            tokens[i] = tokens[i].saturating_add(level.edges[i].produce);
            most[i] = most[i].max(tokens[i]);
        }
    }
    most
}

/// A warning on each channel whose declared capacity is below its bound
/// (`bounds` as given by [`buffer_bounds`]).
pub fn capacity_warnings(level: &Level<'_>, bounds: &[u64]) -> Vec<Diagnostic> {
    let samples = |n: u64| {
        if n == 1 {
            "1 sample".to_string()
        } else {
            format!("{n} samples")
        }
    };
    level
        .edges
        .iter()
        .zip(bounds)
        .filter_map(|(e, &bound)| {
            let capacity = level.graph.channels.get(e.channel?)?.capacity?;
            (capacity < bound).then(|| {
                Diagnostic::new(
                    Code::BufferTooSmall,
                    level.graph.file,
                    e.span,
                    format!(
                        "channel {} holds up to {} under the schedule, but its capacity is {capacity}",
                        e.label,
                        samples(bound)
                    ),
                )
            })
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::super::schedule::flat_schedule;
    use super::super::testing::{channel, graph, task};
    use super::*;
    use crate::span::Span;

    fn bounds_of(g: &crate::taskgraph::model::TaskGraph) -> (Vec<u64>, Vec<Diagnostic>) {
        let level = Level::build(g, None, g.name.clone());
        let counts = super::super::consistency::repetition_vector(&level).unwrap();
        let firings = flat_schedule(&level, &counts).unwrap();
        let bounds = buffer_bounds(&level, &firings);
        let warnings = capacity_warnings(&level, &bounds);
        (bounds, warnings)
    }

    #[test]
    fn multirate_chain_bound_is_the_peak_of_the_flat_schedule() {
        // A makes 2, B takes 3: A A B A B holds 4 at most.
        let g = graph(
            "chain",
            vec![task("A", &["o>2"]), task("B", &["i<3"])],
            vec![channel("A.o", "B.i", 0, 1)],
        );
        let (bounds, warnings) = bounds_of(&g);
        assert_eq!(bounds, [4]);
        assert!(warnings.is_empty());
    }

    #[test]
    fn initial_samples_count_towards_the_bound() {
        let g = graph(
            "loop",
            vec![task("A", &["i<1", "o>1"]), task("B", &["i<1", "o>1"])],
            vec![channel("A.o", "B.i", 0, 1), channel("B.o", "A.i", 3, 2)],
        );
        let (bounds, _) = bounds_of(&g);
        assert_eq!(bounds, [1, 3]);
    }

    #[test]
    fn a_declared_capacity_below_the_bound_is_a_warning_on_the_channel() {
        let mut g = graph(
            "small",
            vec![
                task("A", &["o>6"]),
                task("B", &["i<2", "o>1"]),
                task("C", &["i<3"]),
            ],
            vec![channel("A.o", "B.i", 0, 1), channel("B.o", "C.i", 0, 2)],
        );
        g.channels[0].capacity = Some(4);
        g.channels[1].capacity = Some(3);
        let (bounds, warnings) = bounds_of(&g);
        assert_eq!(bounds, [6, 3]);
        assert_eq!(warnings.len(), 1, "{warnings:?}");
        let w = &warnings[0];
        assert_eq!(w.code, Code::BufferTooSmall);
        assert_eq!(w.span, Span::new(1, 2));
        assert_eq!(
            w.message,
            "channel A.o → B.i holds up to 6 samples under the schedule, but its capacity is 4"
        );
    }

    #[test]
    fn the_w061_fixture_warns_once() {
        let text = include_str!(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../tests/fixtures/diagnostics/W061_buffer_too_small/graph.taskgraph.xml"
        ));
        let (g, loaded) = crate::taskgraph::load_task_graph(crate::diag::FileId(0), text);
        assert!(loaded.is_empty(), "{loaded:?}");
        let (bounds, warnings) = bounds_of(&g.unwrap());
        assert_eq!(bounds, [4]);
        assert_eq!(warnings.len(), 1);
        assert_eq!(
            warnings[0].message,
            "channel A.o → B.i holds up to 4 samples under the schedule, but its capacity is 3"
        );
    }

    #[test]
    fn odd_input_never_panics() {
        let g = graph(
            "odd",
            vec![task("A", &["o>1"]), task("B", &["i<5"])],
            vec![channel("A.o", "B.i", 0, 1)],
        );
        let level = Level::build(&g, None, g.name.clone());
        // Unknown nodes and starving firings.
        assert_eq!(buffer_bounds(&level, &[1, 7, 0, 1]), [1]);
        // Fewer bounds than edges.
        assert!(capacity_warnings(&level, &[]).is_empty());
        let big = graph(
            "big",
            vec![
                task("A", &[&format!("o>{}", u64::MAX)]),
                task("B", &["i<1"]),
            ],
            vec![channel("A.o", "B.i", u64::MAX, 1)],
        );
        let level = Level::build(&big, None, big.name.clone());
        assert_eq!(buffer_bounds(&level, &[0, 0]), [u64::MAX]);
    }
}
