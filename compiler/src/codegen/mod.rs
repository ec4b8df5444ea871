//! Code generation (codegen.md §2–5): each refined robot program becomes a
//! folder of C source that builds with `make` and runs.
//!
//! - `control.rs`: `control_task.c`, the hierarchical state machine.
//! - `files.rs`: `program.h`, `main.c`, `channels.c`, `comm_task.c`, the
//!   library task, the task files and the `Makefile`.
//! - `output.rs`: writing a robot's folder atomically, never overwriting a
//!   file the user owns.
//! - `schedule.rs`: the static schedule's firing order from the SDF analysis.
//! - `target.rs`: what a target refuses (inter-robot messages on bare metal).
//! - `runtime/`: the hand-written C runtime, written once per build into
//!   [`RUNTIME_FOLDER`] beside the team folders, which every robot's
//!   Makefile compiles (`semo_runtime.mk`: objects shared by the robots built
//!   with the same compiler and flags): the portable core and a platform
//!   layer (POSIX threads or a static schedule with a board file).
//!
//! Targets are data: a target is a platform of [`crate::platform::PLATFORMS`]
//! or its simulation (its runtime layer, transport, runtime files, and for a
//! board its toolchain, memory and start-up); the generated code differs
//! only where the platform does (locks, blocking, the schedule table, the
//! Makefile). Each robot of a build has its own target ([`Targets`]: what
//! the door asked, the project file or the robot type's platform); the
//! runtime folder holds what every target used needs.

mod battery;
mod board_link;
mod c;
mod control;
pub(crate) mod files;
mod loops;
pub mod output;
mod peers;
mod schedule;
mod shared;
mod target;
mod template;
mod values;

use crate::refine::{BuildInput, CompiledScenario, Refined, refine_checked, robot_span};
use crate::refine::{RobotProgram, RoleKind};
use crate::targets::{Targets, distinct};
use crate::taskgraph::write::to_xml;

/// The header a threads target's runtime reads its connection defaults from
/// (broker, client id, credentials' paths): generated without any, and
/// filled by `deploy::bake` when `semo build --deploy` names a deployment.
pub const DEPLOY_HEADER: &str = "semo_deploy.h";

/// `text` as a C string literal (escaped), for files written beside the
/// generated code (`deploy::bake`).
pub fn c_string(text: &str) -> String {
    c::string(text)
}

pub use crate::platform::{Layer, Target, Transport};

const API: (&str, &str) = ("semo_runtime.h", include_str!("runtime/semo_runtime.h"));
const INTERNAL: (&str, &str) = ("semo_internal.h", include_str!("runtime/semo_internal.h"));
const CORE: (&str, &str) = ("semo_core.c", include_str!("runtime/semo_core.c"));
const POSIX: (&str, &str) = ("semo_runtime.c", include_str!("runtime/semo_runtime.c"));
const UDP: (&str, &str) = ("semo_udp.c", include_str!("runtime/semo_udp.c"));
const MQTT: (&str, &str) = ("semo_mqtt.c", include_str!("runtime/semo_mqtt.c"));
const LINK_H: (&str, &str) = ("semo_link.h", include_str!("runtime/semo_link.h"));
const LINK: (&str, &str) = ("semo_link.c", include_str!("runtime/semo_link.c"));
const LINK_TRANSPORT: (&str, &str) = (
    "semo_link_transport.c",
    include_str!("runtime/semo_link_transport.c"),
);
const POSIX_SIM: (&str, &str) = ("semo_sim.c", include_str!("runtime/semo_sim.c"));
const LOCKSTEP: (&str, &str) = ("semo_lockstep.c", include_str!("runtime/semo_lockstep.c"));
const STATIC: (&str, &str) = ("semo_static.c", include_str!("runtime/semo_static.c"));
const STATIC_LINK: (&str, &str) = (
    "semo_static_link.c",
    include_str!("runtime/semo_static_link.c"),
);
const STATIC_STATUS: (&str, &str) = (
    "semo_static_status.c",
    include_str!("runtime/semo_static_status.c"),
);
const STATIC_LOCKSTEP: (&str, &str) = (
    "semo_static_lockstep.c",
    include_str!("runtime/semo_static_lockstep.c"),
);
const CORTEX_M: (&str, &str) = ("semo_cortex_m.c", include_str!("runtime/semo_cortex_m.c"));
const LM3S6965: (&str, &str) = ("semo_lm3s6965.c", include_str!("runtime/semo_lm3s6965.c"));
const LM3S6965_LD: (&str, &str) = ("lm3s6965.ld", LINK_SCRIPT.text);
const STM32F405: (&str, &str) = ("semo_stm32f405.c", include_str!("runtime/semo_stm32f405.c"));
const STM32F405_LD: (&str, &str) = ("stm32f405.ld", LINK_SCRIPT.text);
/// A board's link script, its memory map filled in from the platform
/// table's row ([`board_file`]): one template for every board.
const LINK_SCRIPT: template::Template = template::Template {
    path: "runtime/board.ld.in",
    text: include_str!("runtime/board.ld.in"),
    slots: &[
        "ld",
        "board",
        "machine",
        "flash_origin",
        "flash_kib",
        "ram_origin",
        "ram_kib",
        "startup",
    ],
};
/// The make rules every robot's Makefile includes to compile the runtime.
const MAKE_RULES: (&str, &str) = ("semo_runtime.mk", include_str!("runtime/semo_runtime.mk"));

/// Every file of the runtime, whatever the target.
const RUNTIME_FILES: &[(&str, &str)] = &[
    API,
    INTERNAL,
    CORE,
    POSIX,
    UDP,
    MQTT,
    LINK_H,
    LINK,
    LINK_TRANSPORT,
    POSIX_SIM,
    LOCKSTEP,
    STATIC,
    STATIC_LINK,
    STATIC_STATUS,
    STATIC_LOCKSTEP,
    CORTEX_M,
    LM3S6965,
    LM3S6965_LD,
    STM32F405,
    STM32F405_LD,
    MAKE_RULES,
];

/// The folder under the output folder that holds the runtime, once per
/// build, beside the team folders (never a team's: team names are C
/// identifiers). Each robot's Makefile names it `RUNTIME` (`../../` + this).
pub const RUNTIME_FOLDER: &str = "semo-runtime";

/// Whether `name` is a file of the runtime: earlier versions copied the
/// runtime into every robot folder, and a copy left there would shadow the
/// shared one.
pub fn is_runtime_file(name: &str) -> bool {
    RUNTIME_FILES.iter().any(|(file, _)| *file == name)
}

/// The files of [`RUNTIME_FOLDER`] for a build whose robots are generated
/// for `targets`: what each of them compiles, once, and the make rules. A
/// board's link script is written from its row of the platform table.
pub fn runtime_files(targets: &[Target]) -> Vec<GeneratedFile> {
    let used = |name: &str| targets.iter().any(|t| t.runtime().any(|f| f == name));
    RUNTIME_FILES
        .iter()
        .filter(|(name, _)| used(name))
        .chain([&MAKE_RULES])
        .map(|(path, text)| GeneratedFile {
            path: path.to_string(),
            text: board_file(targets, path, text),
            owner: Owner::Generated,
        })
        .collect()
}

/// `text`, the runtime file `path`, with the facts of the board whose link
/// script it is filled in (the slots of [`LINK_SCRIPT`]); other files as
/// they are.
fn board_file(targets: &[Target], path: &'static str, text: &'static str) -> String {
    let board = targets
        .iter()
        .filter_map(|t| t.platform().board.as_ref())
        .find(|b| b.link_script == path);
    match board {
        None => text.to_string(),
        Some(board) => template::fill(
            &template::Template {
                path,
                text,
                ..LINK_SCRIPT
            },
            &[
                ("ld", &board.link_script),
                ("board", &board.name),
                ("machine", &board.machine),
                (
                    "flash_origin",
                    &format_args!("0x{:08X}", board.flash.origin),
                ),
                ("flash_kib", &board.flash.kib),
                ("ram_origin", &format_args!("0x{:08X}", board.ram.origin)),
                ("ram_kib", &board.ram.kib),
                ("startup", &board.startup),
            ],
        ),
    }
}

/// Who owns a generated file.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Owner {
    /// Rewritten by every generation.
    Generated,
    /// A template for the user: written only when the file does not exist.
    User,
}

#[derive(Clone, Debug)]
pub struct GeneratedFile {
    /// Relative to the robot's folder, with `/`.
    pub path: String,
    pub text: String,
    pub owner: Owner,
}

/// A robot's folder: `<team>/<robot>/` under the output folder.
#[derive(Clone, Debug)]
pub struct RobotOutput {
    pub team: String,
    pub robot: String,
    /// What its files were generated for.
    pub target: Target,
    pub files: Vec<GeneratedFile>,
}

impl RobotOutput {
    /// Lines in generated files and in files the user fills.
    pub fn line_counts(&self) -> (usize, usize) {
        let count = |owner| {
            self.files
                .iter()
                .filter(|f| f.owner == owner && (f.path.ends_with(".c") || f.path.ends_with(".h")))
                .map(|f| f.text.lines().count())
                .sum()
        };
        (count(Owner::Generated), count(Owner::User))
    }
}

/// What to write.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Emit {
    /// Everything: C, Makefile, runtime and the refined task graph.
    All,
    /// Only `taskgraph.xml`.
    TaskGraph,
}

/// The files of one robot's folder. `sources` names the input files for the
/// header of every generated file; `scenario` is the world compiled into a
/// target that [`Target::needs_scenario`] (ignored by the others); `fleet`
/// the fleet's table the program's peers are found in. With them, what its
/// code asked the word and peer tables for and they lacked (each refuses
/// the build: `lacking_errors`).
fn generate(
    program: &RobotProgram,
    fleet: &peers::Fleet<'_>,
    target: Target,
    emit: Emit,
    sources: &[String],
    scenario: Option<&CompiledScenario>,
) -> (RobotOutput, Lacking) {
    let header = file_header(program, target, sources, Owner::Generated);
    // One word table and one peer table for every file: what they lacked
    // refuses the build.
    let words = values::Words::of(program);
    let peers = peers::Peers::of(program, fleet);
    let mut files = Vec::new();
    let mut push = |path: &str, text: String, owner: Owner| {
        files.push(GeneratedFile {
            path: path.to_string(),
            text,
            owner,
        })
    };
    let xml_comment = format!(
        "Generated by semo from {} for robot {} ({}, team {}). Do not edit.",
        sources.join(", "),
        program.robot,
        program.robot_type,
        program.team
    );
    push(
        "taskgraph.xml",
        to_xml(&program.graph, &xml_comment),
        Owner::Generated,
    );
    if emit == Emit::TaskGraph {
        let output = RobotOutput {
            team: program.team.clone(),
            robot: program.robot.clone(),
            target,
            files,
        };
        return (output, Lacking::default());
    }
    let mut sources_c = vec![
        "main.c".to_string(),
        "channels.c".into(),
        "control_task.c".into(),
    ];
    push(
        "program.h",
        files::program_h(program, &header),
        Owner::Generated,
    );
    push(
        "main.c",
        files::main_c(program, &words, &peers, target, &header),
        Owner::Generated,
    );
    push(
        "channels.c",
        files::channels_c(program, target, &header),
        Owner::Generated,
    );
    push(
        "control_task.c",
        control::control_task(program, &words, &peers, &header),
        Owner::Generated,
    );
    let comm = program
        .tasks
        .iter()
        .any(|t| matches!(t.kind, RoleKind::CommSend | RoleKind::CommReceive));
    if comm {
        push(
            "comm_task.c",
            files::comm_task_c(program, &words, &peers, target, &header),
            Owner::Generated,
        );
        sources_c.push("comm_task.c".into());
    }
    if let Some((name, text)) = shared::library_c(program, &peers, target, &header) {
        push(&name, text, Owner::Generated);
        sources_c.push(name);
    }
    let mut tasks = Vec::new();
    let task_owner = if target.simulated() {
        Owner::Generated
    } else {
        Owner::User
    };
    let task_header = file_header(program, target, sources, task_owner);
    for role in &program.tasks {
        if let Some(text) = files::task_c(program, role, target, &task_header) {
            let path = format!("tasks/{}.c", role.task);
            push(&path, text, task_owner);
            tasks.push(path);
        }
    }
    if let (true, Some(world)) = (target.needs_scenario(), scenario) {
        push(
            "scenario.c",
            files::scenario_c(world, &header, program, &peers),
            Owner::Generated,
        );
        sources_c.push("scenario.c".into());
    }
    if target.layer() == Layer::Threads {
        push(
            DEPLOY_HEADER,
            "/* No deployment file was given (`semo build --deploy FILE`): the runtime's\n * defaults, options and environment variables decide the connection. */\n".into(),
            Owner::Generated,
        );
    }
    // A board robot that messages no other robot leaves its board's link
    // out.
    let link = target
        .platform()
        .board
        .as_ref()
        .map(|b| &b.link)
        .filter(|_| target::peer_messages(program).is_some());
    let link_only = |name: &str| {
        link.is_none()
            && target
                .platform()
                .board
                .as_ref()
                .is_some_and(|b| b.link.runtime.contains(&name))
    };
    let runtime_c: Vec<&str> = target
        .runtime()
        .filter(|name| name.ends_with(".c") && !link_only(name))
        .collect();
    let simulated_battery =
        target.needs_scenario() && scenario.is_some_and(|w| !w.battery.is_empty());
    let sizes = files::StaticSizes::of(
        program,
        longest_value(&files, scenario),
        link,
        simulated_battery,
    );
    let makefile = files::makefile(
        program,
        target,
        &files::MakeSources {
            robot: &sources_c,
            tasks: &tasks,
            runtime: &runtime_c,
        },
        &header,
        &sizes,
    );
    files.push(GeneratedFile {
        path: "Makefile".to_string(),
        text: makefile,
        owner: Owner::Generated,
    });
    let output = RobotOutput {
        team: program.team.clone(),
        robot: program.robot.clone(),
        target,
        files,
    };
    let lacking = Lacking {
        words: words.missing(),
        peers: peers.missing(),
    };
    (output, lacking)
}

/// What the code generated for a robot asked its tables for and they
/// lacked: generator bugs, each refusing the build (E102).
#[derive(Default)]
struct Lacking {
    /// Words its word table lacks.
    words: Vec<String>,
    /// Robots (fleet indices) its peer table lacks.
    peers: Vec<crate::refine::PeerId>,
}

/// Bytes of the longest value the program holds that is known at build
/// time: the literals of the generated code (`SEMO_LIT("...")`, measured as
/// written, escapes included, so never short) and the scenario's values.
fn longest_value(files: &[GeneratedFile], scenario: Option<&CompiledScenario>) -> usize {
    let literals = files
        .iter()
        .flat_map(|f| f.text.split("SEMO_LIT(\"").skip(1))
        .map(|rest| rest.find("\")").unwrap_or(rest.len()));
    let world = scenario.into_iter().flat_map(|w| {
        w.sensors
            .iter()
            .map(|(_, _, is)| is.len())
            .chain(w.operator.iter().map(|c| c.value.len()))
    });
    literals.chain(world).max().unwrap_or(0)
}

/// The comment every C file written starts with: what it was written for,
/// and what the next `semo build` does to it, which depends on its owner.
fn file_header(program: &RobotProgram, target: Target, sources: &[String], owner: Owner) -> String {
    let (written, next_build) = match owner {
        Owner::Generated => (
            "Generated",
            "Regenerated by `semo build`: edit the mission, not this file.",
        ),
        Owner::User => (
            "Written",
            "Yours to fill: later builds for this target keep it as it is (delete it for a fresh template).",
        ),
    };
    format!(
        "/* {written} by semo for robot {} ({}, team {}), target {}.\n * Sources: {}.\n * {next_build} */\n",
        c::comment(&program.robot),
        c::comment(&program.robot_type),
        c::comment(&program.team),
        target.name(),
        c::comment(&sources.join(", "))
    )
}

/// The outcome of generating a mission's code.
pub struct BuildResult {
    /// One folder per robot, in formation order, each with its target;
    /// empty when generation was refused.
    pub robots: Vec<RobotOutput>,
    /// The files of [`RUNTIME_FOLDER`] the robots compile (what each of
    /// their targets needs); empty when generation was refused or writes
    /// only task graphs.
    pub runtime: Vec<GeneratedFile>,
    /// Why generation was refused (check errors, unsupported constructs,
    /// unsafe names, failing refined graphs), with the check's warnings.
    pub diagnostics: Vec<crate::diag::Diagnostic>,
}

impl BuildResult {
    fn refused_with(diagnostics: Vec<crate::diag::Diagnostic>) -> BuildResult {
        BuildResult {
            robots: Vec::new(),
            runtime: Vec::new(),
            diagnostics,
        }
    }

    pub fn refused(&self) -> bool {
        self.diagnostics
            .iter()
            .any(crate::diag::Diagnostic::is_error)
    }

    /// The targets its robots were generated for, each once, in
    /// [`Target::ALL`]'s order.
    pub fn targets(&self) -> Vec<Target> {
        distinct(self.robots.iter().map(|r| r.target))
    }
}

/// Generates the code of a mission for `target`: every error of the check
/// (in the mission, the catalog or the strategies) refuses generation, as do
/// problems found while refining.
pub fn build(build: &BuildInput<'_>, target: Target, emit: Emit) -> BuildResult {
    build_each(build, &Targets::all(target), emit)
}

/// [`build`] with each robot generated for its own target.
pub fn build_each(build: &BuildInput<'_>, targets: &Targets, emit: Emit) -> BuildResult {
    build_refined_each(build, &refine_checked(build), targets, emit, &[])
}

/// Generates the code of refined programs (from [`refine_checked`]) for
/// `target`, refusing what the target cannot run ([`target::check`]).
/// `scenarios` holds one compiled world per program, in order, for a target
/// that [`Target::needs_scenario`].
pub fn build_refined(
    build: &BuildInput<'_>,
    refined: &Refined,
    target: Target,
    emit: Emit,
    scenarios: &[CompiledScenario],
) -> BuildResult {
    build_refined_each(build, refined, &Targets::all(target), emit, scenarios)
}

/// [`build_refined`] with each robot generated for its own target: one
/// build, the runtime folder holding what each target used needs.
pub fn build_refined_each(
    build: &BuildInput<'_>,
    refined: &Refined,
    targets: &Targets,
    emit: Emit,
    scenarios: &[CompiledScenario],
) -> BuildResult {
    // The refined mission is the host's memoised query, shared by every
    // door: read, never taken.
    let Refined {
        programs,
        diagnostics,
        sources,
    } = refined;
    let mut diagnostics = diagnostics.clone();
    if programs.is_empty() {
        return BuildResult::refused_with(diagnostics);
    }
    let mut chosen = Vec::new();
    for program in programs {
        match targets.of(&program.robot) {
            Some(target) => chosen.push(target.clone()),
            // The plan names every robot of the mission: never a default.
            None => {
                diagnostics.push(crate::diag::Diagnostic::new(
                    crate::diag::Code::CodegenInternal,
                    build.mission,
                    robot_span(build, &program.robot),
                    format!(
                        "robot `{}` has no target in the build's plan",
                        program.robot
                    ),
                ));
                return BuildResult::refused_with(diagnostics);
            }
        }
    }
    diagnostics.extend(target::check(build, programs, &chosen, emit, scenarios));
    crate::diag::sort_and_dedup(&mut diagnostics);
    if diagnostics.iter().any(crate::diag::Diagnostic::is_error) {
        return BuildResult::refused_with(diagnostics);
    }
    let mut robots: Vec<RobotOutput> = Vec::new();
    // Refinement gives every program one fleet table: indexed once.
    let fleet = peers::Fleet::of(&programs[0].peers);
    for (i, (program, chosen)) in programs.iter().zip(&chosen).enumerate() {
        let other;
        let fleet = if fleet.holds(program) {
            &fleet
        } else {
            other = peers::Fleet::of(&program.peers);
            &other
        };
        let (robot, lacking) = generate(
            program,
            fleet,
            chosen.target,
            emit,
            sources,
            scenarios.get(i),
        );
        diagnostics.extend(lacking_errors(build, program, &lacking));
        robots.push(robot);
    }
    diagnostics.extend(
        programs
            .iter()
            .zip(&robots)
            .flat_map(|(program, robot)| written_graph_errors(build, program, robot)),
    );
    if diagnostics.iter().any(crate::diag::Diagnostic::is_error) {
        return BuildResult::refused_with(diagnostics);
    }
    let runtime = match emit {
        Emit::All => runtime_files(&distinct(chosen.iter().map(|c| c.target))),
        Emit::TaskGraph => Vec::new(),
    };
    BuildResult {
        robots,
        runtime,
        diagnostics,
    }
}

/// The words and robots generation asked the program's word and peer
/// tables for and they lacked (`values::Words::index`,
/// `peers::Peers::local`): each an internal error (E102), never written as
/// another word or robot.
fn lacking_errors(
    build: &BuildInput<'_>,
    program: &crate::refine::RobotProgram,
    lacking: &Lacking,
) -> Vec<crate::diag::Diagnostic> {
    use crate::diag::{Code, Diagnostic};
    let span = robot_span(build, &program.robot);
    let robot = &program.robot;
    let words = lacking.words.iter().map(|word| {
        format!("the code generated for robot `{robot}` uses the word `{word}`, which its word table lacks")
    });
    let peers = lacking.peers.iter().map(|&i| {
        let named = program.peers.get(i.index()).map_or("?", |(_, r)| r.as_str());
        format!("the code generated for robot `{robot}` names robot `{named}`, which its peer table lacks")
    });
    words
        .chain(peers)
        .map(|message| Diagnostic::new(Code::CodegenInternal, build.mission, span, message))
        .collect()
}

/// Each robot's `taskgraph.xml` read back by the task-graph loader, as a user
/// opening it would: it holds the rules of the format itself (names unique,
/// channel ends exist, ...) that the analyses assume. Any error there is
/// refinement's fault (E102 on the robot's declaration).
fn written_graph_errors(
    build: &BuildInput<'_>,
    program: &crate::refine::RobotProgram,
    robot: &RobotOutput,
) -> Vec<crate::diag::Diagnostic> {
    use crate::diag::{Code, Diagnostic, FileId};
    let Some(written) = robot.files.iter().find(|f| f.path == "taskgraph.xml") else {
        return Vec::new();
    };
    let (_, loaded) = crate::taskgraph::load_task_graph(FileId(u32::MAX), &written.text);
    let span = robot_span(build, &program.robot);
    loaded
        .iter()
        .filter(|d| d.is_error())
        .map(|d| {
            Diagnostic::new(
                Code::CodegenInternal,
                build.mission,
                span,
                format!(
                    "the task graph written for robot `{}` does not read back: [{}] {}",
                    program.robot, d.code, d.message
                ),
            )
        })
        .collect()
}

/// Every template, for the tests that check them (`template`'s).
#[cfg(test)]
fn all_templates() -> impl Iterator<Item = &'static template::Template> {
    [
        control::TEMPLATES,
        files::TEMPLATES,
        loops::TEMPLATES,
        shared::TEMPLATES,
        battery::TEMPLATES,
        &[LINK_SCRIPT],
    ]
    .into_iter()
    .flatten()
}
