//! The `semo` command: the compiler library's door for people and scripts, and
//! `semo lsp`, the language server's door for editors. Exit codes: 0 no errors,
//! 1 errors found, 2 usage or I/O problem.

mod build;
mod catalog;
mod check;
mod defaults;
mod deploy;
mod fix;
mod fmt;
mod gateway;
mod graph;
mod init;
mod input;
mod lockstep;
mod manual;
mod mcap;
mod operator;
mod output;
mod render;
mod replay;
mod simulate;
mod terminal;
mod verify;
mod watch;

use clap::{CommandFactory, Parser, Subcommand, ValueEnum};
use output::Format;
use std::io::{IsTerminal, Write};
use std::path::PathBuf;
use std::sync::Arc;

#[derive(Parser, Debug)]
#[command(
    name = "semo",
    version = env!("SEMO_VERSION"),
    about = "SeMo: mission scripts for teams of cooperating robots",
    long_about = "SeMo checks mission scripts (*.mission) against a robot catalog (the built-in \
                  one plus any *.robot.xml files) and strategy files (`semo check`), lays them \
                  out canonically (`semo fmt`), refines them into one task graph and C program \
                  per robot (`semo build`), runs them together in virtual time (`semo simulate`), \
                  analyses and draws task graphs and mode machines (`semo graph`), lists the \
                  robot types missions may use (`semo catalog`), explains diagnostic codes \
                  (`semo explain`) and serves editors (`semo lsp`).\n\n\
                  Colour: --color, else NO_COLOR turns it off, CLICOLOR_FORCE on, TERM=dumb \
                  off, and otherwise it is on only on a terminal.\n\nExit status: 0 when no \
                  errors were found, 1 when errors were found, 2 for a usage or I/O problem."
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Check mission scripts, robot catalogs, strategy files and task graphs.
    #[command(
        long_about = "Check mission scripts, robot catalogs, strategy files and task graphs, \
        and report problems.\n\n\
        Each PATH is a file or a folder; a folder stands for every *.mission, *.robot.xml, \
        *.strategy.xml and *.taskgraph.xml file under it. All catalog files found form one \
        catalog (on top of the built-in one), every mission is checked against it, and \
        every strategy file against the catalog and the missions. With no PATH, the \
        current folder is checked. `-` reads a mission from standard input (checked \
        against the built-in catalog alone)."
    )]
    Check {
        /// Files or folders to check (`-`: a mission on standard input).
        paths: Vec<PathBuf>,
        /// How to report: `human` (source snippets and a summary, on standard
        /// error), `json` (one document on standard output, see
        /// docs/diagnostics-json.md) or `sarif` (SARIF 2.1.0, for code scanning).
        #[arg(long, value_enum, default_value_t = Format::Human)]
        format: Format,
        /// Colour the human output: `auto` colours it when writing to a terminal.
        #[arg(long, value_enum, default_value_t = ColorChoice::Auto)]
        color: ColorChoice,
        /// Treat these as errors for the exit status: `warnings` makes any
        /// warning exit with 1.
        #[arg(long, value_enum, value_name = "WHAT")]
        deny: Vec<Deny>,
        /// Check again whenever a mission, catalog, strategy or task-graph
        /// file under the paths changes, until stopped.
        #[arg(long, conflicts_with = "fix")]
        watch: bool,
        /// Apply the fix each problem prefers (the editor's quick fix: a
        /// did-you-mean, a missing `default`, …) to the mission and strategy
        /// files, list what was fixed, and report what is left. A mission on
        /// standard input is printed fixed on standard output.
        #[arg(long)]
        fix: bool,
        /// Instead of each problem, how many there are of each code (and how
        /// many `--fix` would fix).
        #[arg(long)]
        statistics: bool,
    },
    /// Rewrite mission scripts in the canonical layout.
    #[command(
        long_about = "Rewrite mission scripts in the canonical layout (two-space indents, one \
        statement per line, one empty line between items); only spaces and line breaks \
        change, every comment is kept.\n\n\
        Each PATH is a file or a folder; a folder stands for every *.mission file under it, \
        and `-` reads standard input and writes the result to standard output. With no \
        PATH, the current folder. A file is rewritten only when its layout changes; a file \
        with syntax errors is left as it is and reported.\n\n\
        Exit status: 0 when all is formatted, 1 when a file was refused or (with --check or --diff) \
        is not formatted, 2 for a path or I/O problem."
    )]
    Fmt {
        /// Files or folders to format (`-` for standard input).
        paths: Vec<PathBuf>,
        /// Write nothing; list the files whose layout would change, and exit
        /// with 1 if there are any.
        #[arg(long)]
        check: bool,
        /// Print the formatted text instead of rewriting the files.
        #[arg(long, conflicts_with = "check")]
        stdout: bool,
        /// Write nothing; print a unified diff of what formatting would
        /// change (`git apply` takes it), and exit with 1 if there is any.
        #[arg(long, conflicts_with_all = ["check", "stdout"])]
        diff: bool,
    },
    /// Generate the code of a mission: one folder per robot with its refined
    /// task graph and a C program that builds with `make`.
    #[command(
        long_about = "Generate the code of a mission: for every robot, the refined task \
        graph (taskgraph.xml) and a C program (main.c, control_task.c, channels.c, comm_task.c, \
        library and task files, the runtime, a Makefile) in OUT/<Team>/<robot>/.\n\n\
        The catalog (*.robot.xml) and strategy (*.strategy.xml) files beside the mission are \
        read, and those under each --strategy path. Generation is refused while the mission, \
        catalog or strategies have errors. One generation per output folder at a time \
        (OUT/.semo.lock); each robot's folder is replaced atomically, and a later run repairs \
        what an interrupted one left. Task files the user fills (target linux) are created \
        once and never overwritten; a generated file you edited, or a task file of another \
        target, stops generation with its name unless --force (which saves it first)."
    )]
    Build {
        /// The mission script (a file: its folder holds the catalog and
        /// strategy files it reads, so not `-`). Default: the one mission
        /// of the project (under its `semo.toml`, else under the current
        /// folder).
        mission: Option<PathBuf>,
        /// More strategy (and catalog) files or folders to read (not `-`:
        /// they are seen by their paths).
        #[arg(long)]
        strategy: Vec<PathBuf>,
        /// The output folder (default: the project file's `[build] output`,
        /// else `out` beside the mission). `-o` and
        /// `--output` as in every command that writes; `--out` still works.
        #[arg(
            long = "output",
            short = 'o',
            visible_alias = "out",
            value_name = "OUT"
        )]
        out: Option<PathBuf>,
        /// Every robot's target: `linux` (POSIX threads; you fill the task
        /// files), `linux-sim` (sensors, actuators and the operator
        /// simulated from the --scenario compiled in), `cortex-m`
        /// (bare-metal TI Stellaris LM3S6965, a static schedule; you fill
        /// the task files), `stm32f4` (the same on an ST STM32F405) or
        /// `cortex-m-sim`, `stm32f4-sim` (the same with --scenario compiled
        /// in, for QEMU). Default: each robot's own, from the
        /// project file (`[build.targets]` for its team or itself, `[build]
        /// target` for all), else the platform its robot type names in the
        /// catalog (`<Platform target="...">`), else `linux`.
        #[arg(long, value_parser = parse_target)]
        target: Option<semo::codegen::Target>,
        /// Build each robot for its platform's simulation (`linux` →
        /// `linux-sim`, `cortex-m` → `cortex-m-sim`): sensors, services and
        /// the operator from a scenario, a trace written.
        #[arg(long)]
        sim: bool,
        /// The scenario (`*.scenario.json`; `-`: standard input) compiled
        /// into each robot built for a simulation (`--target linux-sim`,
        /// `--target cortex-m-sim`, or `--sim`), and only for such a build;
        /// default: the mission's own, as for `simulate`. The programs read
        /// no scenario file.
        #[arg(long)]
        scenario: Option<PathBuf>,
        /// `all` (C code, Makefile and task graph) or `taskgraph` (only the
        /// refined task graphs).
        #[arg(long, value_enum, default_value_t = EmitArg::All)]
        emit: EmitArg,
        /// `human` (what was written, on standard output; diagnostics on
        /// standard error), `json` (one document: diagnostics and the robots
        /// written) or `sarif` (the diagnostics).
        #[arg(long, value_enum, default_value_t = Format::Human)]
        format: Format,
        #[arg(long, value_enum, default_value_t = ColorChoice::Auto)]
        color: ColorChoice,
        /// Replace files generation would otherwise refuse to (generated
        /// files you edited, task files of another target), saving them first
        /// under OUT/.semo-backup/<time>/.
        #[arg(long)]
        force: bool,
        /// A deployment file (`*.deploy.toml`, docs/deployment.md): its
        /// broker and each robot's credentials become the defaults baked
        /// into the robot folders (`semo_deploy.h`; no secret is copied).
        #[arg(long, value_name = "FILE")]
        deploy: Option<PathBuf>,
    },
    /// Deployment on real networks: the broker's configuration.
    #[command(subcommand)]
    Deploy(DeployCommand),
    /// The operator console of a running mission: send the USER commands
    /// it receives (`NAME VALUE` per line on standard input), print what
    /// robots send(USER, …) and a robot's status when its state, mode or
    /// leader changes.
    Operator {
        /// The mission script.
        mission: PathBuf,
        /// The broker, mqtt://HOST[:PORT] (default: the deployment's, else
        /// mqtt://127.0.0.1:1883).
        #[arg(long, value_name = "URL")]
        broker: Option<String>,
        /// A deployment file: the operator's credentials (and broker).
        #[arg(long, value_name = "FILE")]
        deploy: Option<PathBuf>,
        /// The run to show and command (the robots' `--run`); default: the
        /// newest, followed as newer runs start.
        #[arg(long, value_name = "ID")]
        run: Option<String>,
        /// More strategy (and catalog) files or folders to read.
        #[arg(long)]
        strategy: Vec<PathBuf>,
        #[arg(long, value_enum, default_value_t = ColorChoice::Auto)]
        color: ColorChoice,
    },
    /// Bridge robots on serial links to the MQTT broker: each link is one
    /// robot of the mission, which the gateway speaks for with that robot's
    /// client id, credentials and topics (docs/link.md, docs/gateway.md).
    #[command(
        long_about = "Bridge robots on serial links (docs/link.md) to the MQTT broker. Each \
        --link ROBOT=LINK is one robot of the mission: the gateway is its MQTT client, with its \
        client id and credentials from the deployment file (so the broker's ACL applies to it \
        as to a Linux robot), publishes its sends, publishes and status on its own topics, and \
        passes down the link what the broker delivers to it. A frame never says who sent it: a \
        datagram naming another sender than the link's robot is refused.\n\n\
        LINK is tcp:HOST:PORT (the gateway connects, again when the connection is lost; QEMU's \
        -serial tcp:HOST:PORT,server), listen:HOST:PORT (the gateway listens), or the path of a \
        serial device (set up beforehand: stty -F DEVICE 115200 raw).\n\n\
        Runs until stopped. Exit status: 2 for bad arguments (an unknown robot, a link given \
        twice, a bad LINK or run id, mission errors), 1 when the broker refuses the connection \
        for good (a TLS certificate not trusted)."
    )]
    Gateway {
        /// The mission script.
        mission: PathBuf,
        /// A robot and its link: ROBOT=tcp:HOST:PORT, ROBOT=listen:HOST:PORT
        /// or ROBOT=DEVICE (repeatable).
        #[arg(long = "link", value_name = "ROBOT=LINK")]
        links: Vec<String>,
        /// The broker, mqtt://HOST[:PORT] or mqtts://HOST[:PORT] (default: the
        /// deployment's, else mqtt://127.0.0.1:1883).
        #[arg(long, value_name = "URL")]
        broker: Option<String>,
        /// A deployment file: each robot's client id and credentials (and the broker).
        #[arg(long, value_name = "FILE")]
        deploy: Option<PathBuf>,
        /// The run the robots take part in (their topics' scope; default
        /// $SEMO_RUN, else `default`).
        #[arg(long, value_name = "ID")]
        run: Option<String>,
        /// More strategy (and catalog) files or folders to read.
        #[arg(long)]
        strategy: Vec<PathBuf>,
        #[arg(long, value_enum, default_value_t = ColorChoice::Auto)]
        color: ColorChoice,
    },
    /// Run every robot of a mission together in virtual time on a scenario,
    /// and check the scenario's expectations.
    #[command(
        long_about = "Run every robot of a mission together in virtual time, in milliseconds of \
        wall time: the refined programs `semo build` turns into C, on a scenario file \
        (timed sensor values, service durations, operator commands, network, faults and \
        expectations; see docs/scenario-and-trace.md). Prints each robot's modes and every \
        expectation; --trace writes the trace (JSON lines, as linux-sim programs write it), \
        --svg the timeline.\n\n\
        Exit status: 0 when every expectation holds, 1 when one fails, 2 for bad input \
        (mission errors, a bad scenario, options)."
    )]
    Simulate {
        /// The mission script (a file: its folder holds the catalog and
        /// strategy files it reads, so not `-`). Default: the one mission
        /// of the project (under its `semo.toml`, else under the current
        /// folder).
        mission: Option<PathBuf>,
        /// The scenario file (`*.scenario.json`; `-`: standard input).
        /// Default: `<mission>.scenario.json` beside the mission, else the
        /// only `<mission>.*.scenario.json` there.
        #[arg(long)]
        scenario: Option<PathBuf>,
        /// More strategy (and catalog) files or folders to read (not `-`:
        /// they are seen by their paths).
        #[arg(long)]
        strategy: Vec<PathBuf>,
        /// How much mission time to run: `10min`, `90s`, `500ms`, `1h` (default:
        /// the scenario's duration, else 10min or until every robot finished).
        #[arg(long, value_parser = simulate::parse_duration)]
        until: Option<i64>,
        /// Seeds the message losses; the same seed gives the same run.
        #[arg(long, default_value_t = 0)]
        seed: u64,
        /// `text` (modes per robot, expectations) or `json` (one object).
        #[arg(long, value_enum, default_value_t = SummaryFormat::Text)]
        format: SummaryFormat,
        /// Write the timeline picture (SVG) to this file (`-`: standard output).
        #[arg(long, value_name = "OUT")]
        svg: Option<PathBuf>,
        /// Write the trace (JSON lines) to this file (`-`: standard output).
        #[arg(long, value_name = "FILE")]
        trace: Option<PathBuf>,
        /// Write the run as an MCAP file (`-`: standard output): a channel
        /// per robot and kind, `/<team>/<robot>/modes` ... (see
        /// docs/scenario-and-trace.md).
        #[arg(long, value_name = "FILE")]
        mcap: Option<PathBuf>,
        #[arg(long, value_enum, default_value_t = ColorChoice::Auto)]
        color: ColorChoice,
        /// What runs the robots: `sim`, the simulator, or `c`, the generated
        /// `linux-sim` programs (built with make, run as processes in
        /// lock-step virtual time: the same trace format).
        #[arg(long, value_enum, default_value_t = simulate::Engine::Sim)]
        engine: simulate::Engine,
        /// With `--engine c`: each robot on its own platform's simulation
        /// (the build plan of `semo build --sim`): a board robot's firmware
        /// in QEMU, in the same lock-step (needs arm-none-eabi-gcc and
        /// qemu-system-arm).
        #[arg(long)]
        boards: bool,
    },
    /// Read back the traces of a run (each robot's `--trace` file, or one
    /// merged file), merged by time: the summary and timeline `semo
    /// simulate` gives, and the scenario's expectations checked on the
    /// recorded run.
    #[command(
        long_about = "Read back the traces of a real run: each robot's `--trace` file of the \
        generated programs (or one merged file, or `semo simulate --trace`), merged by time and \
        checked line by line against the mission (a malformed line or a robot the mission does \
        not have is an error at its line and column). Prints the per-robot summary `semo \
        simulate` prints, draws the same timeline (--svg), and checks the scenario's \
        expectations on the recorded run, with the simulator's own checks.\n\n\
        Exit status: 0 every expectation holds, 1 one fails, 2 bad input (mission errors, a \
        bad scenario or trace line, options)."
    )]
    Replay {
        /// The trace files (JSON lines; `-`: standard input), in any number:
        /// their lines are merged by time.
        #[arg(required = true, value_name = "TRACE")]
        traces: Vec<PathBuf>,
        /// The mission script the run ran (a file). Default: the one mission
        /// of the project (under its `semo.toml`, else under the current
        /// folder).
        #[arg(long, value_name = "M")]
        mission: Option<PathBuf>,
        /// The scenario whose expectations are checked (`*.scenario.json`;
        /// `-`: standard input). Default: `<mission>.scenario.json` beside
        /// the mission, else the only `<mission>.*.scenario.json` there;
        /// without one, nothing is expected.
        #[arg(long, value_name = "S")]
        scenario: Option<PathBuf>,
        /// More strategy (and catalog) files or folders to read (not `-`).
        #[arg(long)]
        strategy: Vec<PathBuf>,
        /// `human` (modes per robot, expectations) or `json` (one object,
        /// as `semo simulate --format json`).
        #[arg(long, value_enum, default_value_t = DataFormat::Human)]
        format: DataFormat,
        /// Write the timeline picture (SVG) to this file (`-`: standard output).
        #[arg(long, value_name = "OUT")]
        svg: Option<PathBuf>,
        /// Write the run as an MCAP file (`-`: standard output), as
        /// `semo simulate --mcap` does.
        #[arg(long, value_name = "FILE")]
        mcap: Option<PathBuf>,
        #[arg(long, value_enum, default_value_t = ColorChoice::Auto)]
        color: ColorChoice,
    },
    /// Explore everything a mission's team can do (on the simulator's
    /// semantics) and report what no single run shows.
    #[command(
        long_about = "Explore everything a mission's team can do: the refined programs `semo \
        simulate` runs, under every choice of the world (each sensor value a robot compares, \
        in each class its comparisons tell apart; each operator command a robot reads), one \
        choice per step of the world's clock. States met before are not explored again, so \
        a mission that repeats itself is explored completely (a proof for those choices), \
        else up to --horizon, --max-states or --max-memory (bounded; the report says which). Reports a \
        mode no robot of its team ever enters (V001), a robot that can reach a state \
        from which it never finishes though it finishes in other behaviours (V002), and a \
        robot that can reach a `receive` where it waits for ever (V003). With --faults N the \
        world may also kill, restart or cut off robots, up to N times along a behaviour, and \
        two robots leading one `leader(...)` statement at once is reported (V004); with \
        --network N the network may lose or delay the messages of two robots for a step, up \
        to N times. --expect SCENARIO checks that scenario's `expect` list over every behaviour (`always`, \
        `eventually`, `leads_to`; a broken one exits 1 with a scenario that replays it). A \
        plan's `throw` that ends its mode in the instant another plan of the mode would \
        send or throw is reported too (V005: the plans' order decides a race), and so is \
        a robot that takes messages of two robots in one instant and would react otherwise \
        had the network brought them the other way round (V006: a race between robots). \
        --counterexamples DIR writes, per finding, the \
        scenario `semo simulate` replays to it (see docs/verify.md).\n\n\
        Exit status: 0 nothing found, 1 a finding, 2 bad input (mission errors, options)."
    )]
    Verify {
        /// The mission script (a file: its folder holds the catalog and
        /// strategy files it reads). Default: the project's one mission.
        mission: Option<PathBuf>,
        /// More strategy (and catalog) files or folders to read.
        #[arg(long)]
        strategy: Vec<PathBuf>,
        /// How to report: `human`, `json` (one document, docs/diagnostics-json.md)
        /// or `sarif`.
        #[arg(long, value_enum, default_value_t = Format::Human)]
        format: Format,
        /// The world's clock: it may make one choice every STEP (a multiple of 100ms).
        #[arg(long, value_parser = simulate::parse_duration, default_value = "500ms")]
        step: i64,
        /// Mission time beyond which nothing is explored.
        #[arg(long, value_parser = simulate::parse_duration, default_value = "2min")]
        horizon: i64,
        /// States beyond which the search stops.
        #[arg(long, default_value_t = 50_000)]
        max_states: usize,
        /// Memory beyond which the search stops: about what the states it
        /// keeps to explore and its graph of states met hold (`512MB`,
        /// `2GB`; a state of a 20-robot mission is about 70 KB).
        #[arg(long, value_parser = verify::parse_bytes, default_value = "1GiB")]
        max_memory: usize,
        /// How many times after the start the world may choose along one
        /// behaviour (a sensor value into another class, an operator command).
        #[arg(long, default_value_t = 2)]
        changes: u32,
        /// How many faults the world may make along one behaviour: kill a
        /// running robot, restart a killed one, cut one robot off from the
        /// others, heal the cut.
        #[arg(long, default_value_t = 0)]
        faults: u32,
        /// How many times the network may misbehave along one behaviour:
        /// lose, or delay by one step, the messages two robots exchange
        /// during one step.
        #[arg(long, default_value_t = 0)]
        network: u32,
        /// Merge only states of one instant: the search without its
        /// reduction (states met at different instants that would go on
        /// alike merged), to compare the two; it finds the same, with more
        /// states.
        #[arg(long)]
        no_reduction: bool,
        /// Write each finding's counterexample into DIR as a scenario file.
        #[arg(long, value_name = "DIR")]
        counterexamples: Option<PathBuf>,
        /// Check the `expect` list of this scenario file over every
        /// behaviour (`always`, `eventually`, `leads_to`, `enters`,
        /// `never_enters`, `receives`); the rest of the file is not read.
        #[arg(long, value_name = "SCENARIO")]
        expect: Option<PathBuf>,
        #[arg(long, value_enum, default_value_t = ColorChoice::Auto)]
        color: ColorChoice,
    },
    /// Analyse task graphs (`*.taskgraph.xml` or SDF3 files).
    #[command(subcommand)]
    Graph(GraphCommand),
    /// Run the language server on stdin/stdout (for editors).
    Lsp {
        /// Accepted because editors pass it; stdio is the only transport.
        #[arg(long)]
        stdio: bool,
    },
    /// Start a project: write `semo.toml`, a first mission and a catalog in
    /// DIR (default: the current folder).
    #[command(
        long_about = "Start a project: write semo.toml (the project file: catalog and strategy \
        folders, output folder, target, lint levels; see docs/project-file.md), main.mission \
        and robots/rover.robot.xml in DIR (default: the current folder, created if missing). \
        `semo check DIR` accepts them as written.\n\n\
        Nothing is overwritten: if any of these files exists, nothing is written and the \
        exit status is 1."
    )]
    Init {
        /// The project's folder.
        dir: Option<PathBuf>,
    },
    /// List the robot types missions may use: their services (with
    /// signatures) and values (with types), from the built-in catalog and
    /// the project's catalog files.
    #[command(
        long_about = "List the robot types missions may use, with their services (signatures) \
        and values (types and units): the built-in catalog, and the project's own catalog \
        files (*.robot.xml under the catalog folders of the semo.toml above the current \
        folder, else under the current folder), which add types or replace built-in ones. \
        Each type says where it is written. The operator console, USER, is listed apart: it \
        is no robot type; its values are what missions receive from it.\n\n\
        Exit status: 0, 1 when a catalog file has errors (listed on standard error; the \
        types that loaded are still shown), 2 for an unknown TYPE or an I/O problem."
    )]
    Catalog {
        /// One robot type, by name or alias (`USER`: the operator console).
        #[arg(value_name = "TYPE")]
        robot_type: Option<String>,
        /// `human` (the listing on standard output) or `json` (one
        /// document: the catalog files' diagnostics, `robots` and `operator`).
        #[arg(long, value_enum, default_value_t = DataFormat::Human)]
        format: DataFormat,
        #[arg(long, value_enum, default_value_t = ColorChoice::Auto)]
        color: ColorChoice,
    },
    /// Explain a diagnostic code (e.g. `semo explain E019`): what it means,
    /// a wrong and a right example; with no code, list them all.
    Explain {
        /// A code such as E019; all codes when omitted.
        code: Option<String>,
    },
    /// Print the shell completion script for SHELL on standard output.
    #[command(
        long_about = "Print the completion script of `semo` for SHELL on standard output: its \
        commands, options and their values. For example `semo completions bash > \
        ~/.local/share/bash-completion/completions/semo`, `semo completions zsh > \
        ~/.zfunc/_semo` (with ~/.zfunc in fpath) or `semo completions fish > \
        ~/.config/fish/completions/semo.fish`."
    )]
    Completions {
        /// bash, zsh, fish, elvish or powershell.
        shell: clap_complete::Shell,
    },
    /// Print the manual page of `semo` (roff), or with -o write one page
    /// per command into a folder.
    #[command(
        long_about = "Print the manual page semo(1) in roff on standard output (`semo man | man \
        -l -`), or with -o DIR write semo.1 and one page per command (semo-check.1, \
        semo-build.1, …) into DIR, for example ~/.local/share/man/man1."
    )]
    Man {
        /// The folder to write every page into (created if missing).
        #[arg(long = "output", short = 'o', value_name = "DIR")]
        out: Option<PathBuf>,
    },
}

#[derive(Subcommand, Debug)]
enum DeployCommand {
    /// Write a mosquitto configuration (`mosquitto.conf`) and its ACL
    /// (`semo.acl`) for a mission: each robot's user may write only its own
    /// topics and read what is sent to it, only the operator may write USER
    /// commands, anonymous clients are refused, TCP_NODELAY is on.
    BrokerConfig {
        /// The mission script.
        mission: PathBuf,
        /// The deployment file (`*.deploy.toml`).
        #[arg(long, value_name = "FILE")]
        deploy: PathBuf,
        /// More strategy (and catalog) files or folders to read.
        #[arg(long)]
        strategy: Vec<PathBuf>,
        /// The folder to write the configuration into.
        #[arg(long = "output", short = 'o', value_name = "DIR")]
        out: PathBuf,
        #[arg(long, value_enum, default_value_t = ColorChoice::Auto)]
        color: ColorChoice,
    },
}

#[derive(Subcommand, Debug)]
enum GraphCommand {
    /// Consistency (repetition vector per level) and deadlock freedom of a
    /// task graph, with diagnostics on the channel concerned.
    Analyze {
        /// A `*.taskgraph.xml` file or an SDF3 graph (`<sdf3 type="sdf">`;
        /// `-`: standard input).
        file: PathBuf,
        /// `human` (diagnostics on standard error, the analysis on standard
        /// output), `json` (one document: diagnostics and levels) or `sarif`.
        #[arg(long, value_enum, default_value_t = Format::Human)]
        format: Format,
        #[arg(long, value_enum, default_value_t = ColorChoice::Auto)]
        color: ColorChoice,
        #[command(flatten)]
        reading: ReadingArgs,
    },
    /// A static schedule: the looped single-appearance schedule of the whole
    /// graph (`A 10(B C) D`), and with `--cores N` each level's iteration
    /// scheduled onto N cores (task@start time).
    Schedule {
        /// A `*.taskgraph.xml` file or an SDF3 graph (`-`: standard input).
        file: PathBuf,
        /// Also schedule each level onto this many cores.
        #[arg(long)]
        cores: Option<usize>,
    },
    /// The buffer/throughput trade-off of the graph's top level (SDF3's buffer
    /// sizing model): the exact Pareto front (total buffer size → iteration
    /// period) where its exploration fits the budget, else distributions
    /// found (upper bounds), which the output says; the smallest total size
    /// reaching the maximal throughput (exact, or between stated bounds),
    /// and the channel sizes of a chosen point.
    Buffers {
        /// A `*.taskgraph.xml` file or an SDF3 graph (`-`: standard input).
        file: PathBuf,
        /// The point whose channel sizes are listed: `max` (the maximal
        /// throughput) or a throughput in iterations per time unit (`1/104`,
        /// `0.0096`): the smallest point found reaching at least it.
        #[arg(long, default_value = "max")]
        throughput: String,
        /// `human` or `json` (one document: diagnostics and the trade-off).
        #[arg(long, value_enum, default_value_t = DataFormat::Human)]
        format: DataFormat,
        #[command(flatten)]
        reading: ReadingArgs,
    },
    /// The latency from one task of the graph's top level to another: the
    /// minimal and the self-timed latency, as SDF3 defines them.
    #[command(long_about = LATENCY_HELP)]
    Latency {
        /// A `*.taskgraph.xml` file or an SDF3 graph (`-`: standard input).
        file: PathBuf,
        /// The source task (a sensor's, say).
        #[arg(long, value_name = "TASK")]
        from: String,
        /// The sink task (the actuator's command it causes).
        #[arg(long, value_name = "TASK")]
        to: String,
        /// `human` or `json` (one document: diagnostics and the latencies).
        #[arg(long, value_enum, default_value_t = DataFormat::Human)]
        format: DataFormat,
        #[command(flatten)]
        reading: ReadingArgs,
    },
    /// Print the graph in Graphviz DOT: tasks, loop nodes as clusters, rates
    /// and initial samples on channels (`semo graph dot g.taskgraph.xml | dot -Tsvg`).
    Dot {
        /// A `*.taskgraph.xml` file or an SDF3 graph (`-`: standard input).
        file: PathBuf,
    },
    /// Draw the graph as SVG, without Graphviz: tasks, loop nodes as
    /// clusters, rates and initial samples on channels.
    Svg {
        /// A `*.taskgraph.xml` file or an SDF3 graph (`-`: standard input).
        file: PathBuf,
        /// Write the SVG to this file instead of standard output (`-`:
        /// standard output).
        #[arg(short, long, value_name = "FILE")]
        output: Option<PathBuf>,
    },
    /// Draw a mission's mode machines as SVG: each team's modes, the default
    /// mode marked, and the mode changes of its `main` labelled with their
    /// events.
    Modes {
        /// A mission script (`*.mission`; `-`: standard input, checked
        /// against the built-in catalog alone).
        file: PathBuf,
        /// Draw only this team.
        #[arg(long, value_name = "TEAM")]
        team: Option<String>,
        /// Write the SVG to this file instead of standard output (`-`:
        /// standard output).
        #[arg(short, long, value_name = "FILE")]
        output: Option<PathBuf>,
    },
}

/// `semo graph latency --help`: the definitions computed.
const LATENCY_HELP: &str = "The latency from one task of the graph's top level (--from, the \
source) to another (--to, the sink), as SDF3 defines it (Stuijk et al.), the graph executed as \
its throughput is: unbounded channels, each task firing as soon as its input samples are there \
(--concurrency). Firings are numbered from 0; gamma is the repetition vector.

Offset: with the source held back, the sink completes d firings fed by initial samples alone; \
the source's iteration k (its firing gamma(source)*k) is closed by the sink's firing \
gamma(sink)*k + delta, delta = floor(d/gamma(sink))*gamma(sink) + gamma(sink) - 1.

Minimal latency: from that held-back state (everything idle), the source let go for one \
iteration at time 0, the time at which the sink's firing delta ends, every firing as early as \
possible: one iteration alone in an idle graph.

Self-timed latency: in the self-timed execution from the initial samples, the largest, over \
every iteration k, of the end of the sink's firing gamma(sink)*k + delta minus the start of the \
source's firing gamma(source)*k (the transient included). It is unbounded where a task before \
the sink is slower than the source; it is not computed where a task the source does not feed \
runs ahead of the sink's pace (its samples pile up) or nothing bounds the pace.

Only tasks the sink depends on count (for the minimal latency, those the source also feeds); \
on a strongly connected graph this is SDF3's definition exactly. Exit status: 0 with a minimal \
latency, 1 when there is none (no path from the source to the sink, a graph with errors, an \
inconsistent or deadlocking graph, the work budget), 2 for an unknown task or file.";

/// How an analysed graph file is read: its concurrency and, for SDF3 files,
/// which execution time an actor has.
#[derive(clap::Args, Debug, Clone, Copy)]
struct ReadingArgs {
    /// Whether a task fires concurrently with itself: `auto` (SDF3's
    /// meaning: as often as its input samples allow, unless a self-loop
    /// channel limits it) or `single` (one firing at a time, as the generated
    /// code runs a task). Default: `auto` for SDF3 files, `single` for
    /// `*.taskgraph.xml`.
    #[arg(long, value_enum)]
    concurrency: Option<ConcurrencyArg>,
    /// Read SDF3 execution times as SDF3's own loader does (the last
    /// `<processor>` with a `default` attribute, whatever its value) instead
    /// of the one marked `default="true"`.
    #[arg(long)]
    sdf3_compat: bool,
}

impl ReadingArgs {
    fn reading(self) -> semo::workspace::GraphReading {
        use semo::taskgraph::analysis::Concurrency;
        semo::workspace::GraphReading {
            concurrency: self.concurrency.map(|c| match c {
                ConcurrencyArg::Auto => Concurrency::Auto,
                ConcurrencyArg::Single => Concurrency::Single,
            }),
            times: if self.sdf3_compat {
                semo::taskgraph::ExecutionTimes::Sdf3Compat
            } else {
                semo::taskgraph::ExecutionTimes::FileDefault
            },
        }
    }
}

#[derive(Clone, Copy, Debug, ValueEnum, PartialEq, Eq)]
enum ConcurrencyArg {
    Auto,
    Single,
}

#[derive(Clone, Copy, Debug, ValueEnum, PartialEq, Eq)]
enum DataFormat {
    Human,
    Json,
}

#[derive(Clone, Copy, Debug, ValueEnum, PartialEq, Eq)]
enum SummaryFormat {
    Text,
    Json,
}

#[derive(Clone, Copy, Debug, ValueEnum, PartialEq, Eq)]
enum Deny {
    Warnings,
}

#[derive(Clone, Copy, Debug, ValueEnum, PartialEq, Eq)]
enum ColorChoice {
    Auto,
    Always,
    Never,
}

/// mimalloc rather than the C library's malloc: most of what `semo` does
/// is small allocations (see the workspace's Cargo.toml for the figures).
#[global_allocator]
static ALLOCATOR: mimalloc::MiMalloc = mimalloc::MiMalloc;

fn main() {
    std::process::exit(run());
}

/// Runs the command line and gives the process exit code.
fn run() -> i32 {
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) => {
            let _ = e.print();
            return if e.use_stderr() { 2 } else { 0 };
        }
    };
    let stdout = std::io::stdout();
    let mut out = stdout.lock();
    let code = match cli.command {
        Command::Check {
            paths,
            format,
            color,
            deny,
            watch,
            fix,
            statistics,
        } => {
            let options = check::Options {
                format,
                color: use_color(color),
                deny_warnings: deny.contains(&Deny::Warnings),
                fix,
                statistics,
            };
            if watch {
                watch::run(&paths, || {
                    let code = check::run(paths.clone(), options, &mut out);
                    let _ = out.flush();
                    code
                })
            } else {
                check::run_once(paths, options, &mut out)
            }
        }
        Command::Fmt {
            paths,
            check,
            stdout,
            diff,
        } => {
            let mode = match (check, stdout, diff) {
                (true, _, _) => fmt::Mode::Check,
                (_, true, _) => fmt::Mode::Stdout,
                (_, _, true) => fmt::Mode::Diff,
                _ => fmt::Mode::InPlace,
            };
            fmt::run(paths, mode, &mut out)
        }
        Command::Graph(GraphCommand::Analyze {
            file,
            format,
            color,
            reading,
        }) => graph::analyze(&file, reading.reading(), format, use_color(color), &mut out),
        Command::Graph(GraphCommand::Dot { file }) => graph::dot(&file, &mut out),
        Command::Graph(GraphCommand::Svg { file, output }) => {
            graph::svg(&file, output.as_deref(), &mut out)
        }
        Command::Graph(GraphCommand::Modes { file, team, output }) => {
            graph::modes(&file, team.as_deref(), output.as_deref(), &mut out)
        }
        Command::Graph(GraphCommand::Schedule { file, cores }) => {
            graph::schedule(&file, cores, &mut out)
        }
        Command::Graph(GraphCommand::Buffers {
            file,
            throughput,
            format,
            reading,
        }) => graph::buffers(
            &file,
            reading.reading(),
            &throughput,
            format == DataFormat::Json,
            &mut out,
        ),
        Command::Graph(GraphCommand::Latency {
            file,
            from,
            to,
            format,
            reading,
        }) => graph::latency(
            &file,
            reading.reading(),
            &from,
            &to,
            format == DataFormat::Json,
            &mut out,
        ),
        Command::Build {
            mission,
            strategy,
            out: out_dir,
            target,
            sim,
            scenario,
            emit,
            format,
            color,
            force,
            deploy,
        } => build::run(
            build::Options {
                mission,
                strategy,
                out: out_dir,
                target,
                sim,
                scenario,
                deploy,
                emit: match emit {
                    EmitArg::All => semo::codegen::Emit::All,
                    EmitArg::Taskgraph => semo::codegen::Emit::TaskGraph,
                },
                format,
                color: use_color(color),
                force,
            },
            &mut out,
        ),
        Command::Operator {
            mission,
            broker,
            deploy,
            run,
            strategy,
            color,
        } => operator::run(
            operator::Options {
                mission,
                strategy,
                broker,
                deploy,
                run,
                color: use_color(color),
            },
            &mut out,
        ),
        Command::Gateway {
            mission,
            links,
            broker,
            deploy,
            run,
            strategy,
            color,
        } => gateway::run(
            gateway::Options {
                mission,
                strategy,
                links,
                broker,
                deploy,
                run,
                color: use_color(color),
            },
            &mut out,
        ),
        Command::Deploy(DeployCommand::BrokerConfig {
            mission,
            deploy,
            strategy,
            out: out_dir,
            color,
        }) => deploy::broker_config(
            &mission,
            &strategy,
            &deploy,
            &out_dir,
            use_color(color),
            &mut out,
        ),
        Command::Simulate {
            mission,
            scenario,
            strategy,
            until,
            seed,
            format,
            svg,
            trace,
            mcap,
            color,
            engine,
            boards,
        } => simulate::run(
            simulate::Options {
                mission,
                scenario,
                strategy,
                until_ms: until,
                seed,
                json: format == SummaryFormat::Json,
                svg,
                trace,
                mcap,
                color: use_color(color),
                engine,
                boards,
            },
            &mut out,
        ),
        Command::Replay {
            traces,
            mission,
            scenario,
            strategy,
            format,
            svg,
            mcap,
            color,
        } => replay::run(
            replay::Options {
                traces,
                mission,
                scenario,
                strategy,
                json: format == DataFormat::Json,
                svg,
                mcap,
                color: use_color(color),
            },
            &mut out,
        ),
        Command::Verify {
            mission,
            strategy,
            format,
            step,
            horizon,
            max_states,
            max_memory,
            changes,
            faults,
            network,
            no_reduction,
            counterexamples,
            expect,
            color,
        } => verify::run(
            verify::Options {
                mission,
                strategy,
                format,
                color: use_color(color),
                search: semo::verify::Options {
                    step_ms: step,
                    horizon_ms: horizon,
                    max_states,
                    max_memory,
                    changes,
                    faults,
                    network,
                    merge_in_time: !no_reduction,
                    observe: false,
                    cancel: None,
                },
                counterexamples,
                expect,
            },
            &mut out,
        ),
        Command::Explain { code } => explain(code.as_deref(), &mut out),
        Command::Completions { shell } => manual::completions(Cli::command(), shell, &mut out),
        Command::Man { out: dir } => manual::man(Cli::command(), dir.as_deref(), &mut out),
        Command::Catalog {
            robot_type,
            format,
            color,
        } => catalog::run(
            robot_type.as_deref(),
            format == DataFormat::Json,
            use_color(color),
            &mut out,
        ),
        Command::Init { dir } => init::run(dir, &mut out),
        Command::Lsp { stdio: _ } => {
            // The protocol owns stdout from here on.
            drop(out);
            return semo_server::run_stdio();
        }
    };
    let _ = out.flush();
    code
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
enum EmitArg {
    All,
    Taskgraph,
}

/// The files `mission` is built with, from an analysis that loaded and
/// checked it; a mission the analysis lacks is an internal error (exit 2).
fn build_files(
    analysis: &semo::host::Analysis,
    mission: semo::diag::FileId,
) -> Result<semo::host::BuildFiles, i32> {
    analysis.build_input(mission).ok_or_else(|| {
        eprintln!("internal error: the mission was loaded but not checked");
        2
    })
}

/// The refined programs of a loaded mission, for the commands that run
/// them (`simulate`, `verify`, `replay`): the workspace analysis's memoised
/// query (`Analysis::refined`), the one every door asks. On errors, they
/// are reported in `format` and the exit status (2) is returned.
fn refine_or_report(
    check: &mut semo::host::CheckRun,
    mission: semo::diag::FileId,
    format: Format,
    color: bool,
    command: &str,
    out: &mut impl Write,
) -> Result<(semo::host::BuildFiles, Arc<semo::refine::Refined>), i32> {
    let analysis = check.analysis();
    let build = build_files(&analysis, mission)?;
    let Some(refined) = analysis.refined(mission) else {
        eprintln!("internal error: the mission was loaded but not checked");
        return Err(2);
    };
    if refined.diagnostics.iter().any(|d| d.is_error()) {
        check.diagnostics = refined.diagnostics.clone();
        let reported = match format {
            Format::Human | Format::Concise => {
                render::human(check, format, color, &mut std::io::stderr().lock())
            }
            _ => output::report(
                format,
                command,
                &check.files,
                &check.diagnostics,
                color,
                serde_json::json!({}),
                out,
            ),
        };
        let _ = output::written(reported);
        eprintln!("error: cannot {command}: fix the errors above first");
        return Err(2);
    }
    Ok((build, refined))
}

fn parse_target(name: &str) -> Result<semo::codegen::Target, String> {
    semo::codegen::Target::from_name(name).ok_or_else(|| {
        let names: Vec<&str> = semo::codegen::Target::names().collect();
        format!("unknown target `{name}` (targets: {})", names.join(", "))
    })
}

fn use_color(choice: ColorChoice) -> bool {
    let var = |name: &str| std::env::var_os(name).filter(|v| !v.is_empty());
    colour_auto(
        choice,
        var("NO_COLOR").is_some(),
        var("CLICOLOR_FORCE").is_some_and(|v| v != "0"),
        std::env::var_os("TERM").is_some_and(|t| t == "dumb"),
        std::io::stderr().is_terminal(),
    )
}

/// Whether to colour: an explicit `--color` wins; else `NO_COLOR` (set, not
/// empty) turns it off, `CLICOLOR_FORCE` (set, not `0`) on, `TERM=dumb` off,
/// and otherwise a terminal decides (no-color.org, bixense.com/clicolors).
fn colour_auto(
    choice: ColorChoice,
    no_color: bool,
    force: bool,
    dumb: bool,
    terminal: bool,
) -> bool {
    match choice {
        ColorChoice::Always => true,
        ColorChoice::Never => false,
        ColorChoice::Auto => !no_color && (force || (!dumb && terminal)),
    }
}

fn explain(code: Option<&str>, out: &mut impl Write) -> i32 {
    use semo::diag::Code;
    let codes: Vec<Code> = match code {
        None => Code::ALL.to_vec(),
        Some(c) => match Code::from_code(&c.to_ascii_uppercase()) {
            Some(code) => vec![code],
            None => {
                eprintln!("error: unknown diagnostic code `{c}` (run `semo explain` to list them)");
                return 2;
            }
        },
    };
    let full = code.is_some();
    for code in codes {
        let _ = writeln!(
            out,
            "{code} ({}): {}",
            code.default_severity(),
            code.summary()
        );
        // One code: its whole explanation, with a wrong and a right example.
        if full {
            let _ = write!(out, "\n{}", code.explanation());
        }
    }
    0
}

#[cfg(test)]
mod tests {
    use super::{ColorChoice, colour_auto};

    #[test]
    fn colour_follows_the_flag_then_the_environment_then_the_terminal() {
        use ColorChoice::*;
        // (choice, NO_COLOR, CLICOLOR_FORCE, TERM=dumb, terminal) → colour
        let cases = [
            (Always, true, false, true, false, true),
            (Never, false, true, false, true, false),
            (Auto, false, false, false, true, true),
            (Auto, false, false, false, false, false),
            (Auto, true, true, false, true, false),
            (Auto, false, true, false, false, true),
            (Auto, false, true, true, false, true),
            (Auto, false, false, true, true, false),
        ];
        for (choice, no, force, dumb, tty, want) in cases {
            assert_eq!(
                colour_auto(choice, no, force, dumb, tty),
                want,
                "{choice:?} NO_COLOR={no} CLICOLOR_FORCE={force} dumb={dumb} tty={tty}"
            );
        }
    }
}
