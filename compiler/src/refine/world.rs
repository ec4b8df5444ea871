//! The world of one robot, compiled from a scenario: what its simulated
//! program is told instead of sensing, serving and hearing the operator
//! (sensor values, service times, battery levels, loop exits, the
//! operator's commands, link faults). Both back ends read it: the C
//! generator writes it as `scenario.c` into a robot built for a simulated
//! target (`codegen`), and the simulator's scenario reader (`sim`) makes it
//! from a scenario file (`sim::scenario::Scenario::compiled_for`) and
//! applies its link faults. It lives here, below both, so neither back end
//! reads the other.

/// The world of one robot from a scenario, compiled into its simulated
/// program (`scenario.c`, read by both simulation runtimes: no program
/// reads a scenario file). The simulator's scenario reader (`sim`) makes
/// it from a scenario file: `sim::scenario::Scenario::compiled_for`.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct CompiledScenario {
    /// Mission ms the run lasts; `None`: until the robot stops itself.
    pub duration_ms: Option<i64>,
    /// Wall ms per mission ms on the wall clock; `None`: 1 (the program's
    /// `--time-scale` overrides it).
    pub time_scale: Option<f64>,
    /// (at, value name, value), in file order.
    pub sensors: Vec<(i64, String, String)>,
    /// (service, ms).
    pub services: Vec<(String, i64)>,
    /// (service, what each of its calls gives back, in call order): the
    /// `n`th call's values in the order of the service's results (`None`,
    /// none); calls past the list give the last entry again, and a service
    /// without one gives none.
    pub results: Vec<(String, CallResults)>,
    /// (at, level), in time order: the `BATTERY` value, linear between.
    pub battery: Vec<(i64, f64)>,
    /// (SDF/L loop path, the iteration whose exit task sets the exit flag).
    pub loops: Vec<(String, u64)>,
    /// The operator's commands to this robot or its team.
    pub operator: Vec<OperatorCommand>,
    /// The link faults on this robot's messages, in file order.
    pub links: Vec<CompiledLink>,
}

/// What a service's calls give back, per call done in order: each call's
/// values in the order of the service's results (`None`: none).
pub type CallResults = Vec<Vec<Option<String>>>;

/// A link fault on the messages this robot sends to `robots` during
/// [`from`, `until`).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct CompiledLink {
    pub effect: LinkEffect,
    pub from: i64,
    pub until: i64,
    /// By name; those the program never sends to are not written.
    pub robots: Vec<String>,
}

/// What a link fault does to a message.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LinkEffect {
    Lost,
    /// Arrives this many ms late.
    Delayed(i64),
}

/// `key` (`USER.<value>`) = `value`, first at `first`, then every `every`
/// ms while at most `until`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct OperatorCommand {
    pub key: String,
    pub value: String,
    pub first: i64,
    pub every: Option<i64>,
    pub until: i64,
}
