//! Diagnostics as data: one type used by every layer. Each code is listed once in
//! [`codes!`] with its stable name, default severity and a one-line summary; the CLI
//! (ariadne, JSON) and the language server render the same values.

use crate::span::Span;
use std::fmt;

/// Which file a diagnostic points into. The caller that loads files assigns them.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Default)]
pub struct FileId(pub u32);

#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Severity {
    Error,
    Warning,
    Hint,
}

impl Severity {
    pub fn as_str(self) -> &'static str {
        match self {
            Severity::Error => "error",
            Severity::Warning => "warning",
            Severity::Hint => "hint",
        }
    }
}

impl fmt::Display for Severity {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

macro_rules! codes {
    ($($variant:ident = $code:literal, $severity:ident, $summary:literal;)*) => {
        /// Every diagnostic the toolchain can report. The string code is stable.
        #[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
        pub enum Code {
            $($variant,)*
        }

        impl Code {
            pub const ALL: &'static [Code] = &[$(Code::$variant,)*];

            /// The stable code, e.g. `E010`.
            pub fn as_str(self) -> &'static str {
                match self { $(Code::$variant => $code,)* }
            }

            pub fn default_severity(self) -> Severity {
                match self { $(Code::$variant => Severity::$severity,)* }
            }

            /// What the code means, in one line (for `--explain`-style listings).
            pub fn summary(self) -> &'static str {
                match self { $(Code::$variant => $summary,)* }
            }

            pub fn from_code(code: &str) -> Option<Code> {
                match code { $($code => Some(Code::$variant),)* _ => None }
            }

            /// The full explanation (`semo explain CODE`): what the code
            /// means and why, then a `## Wrong` and a `## Right` example,
            /// each one or more files in fenced blocks whose info string is
            /// the file name. One file per code, `diag/explain/CODE.md`: a
            /// code without one does not compile.
            pub fn explanation(self) -> &'static str {
                match self {
                    $(Code::$variant => include_str!(concat!("diag/explain/", $code, ".md")),)*
                }
            }
        }
    };
}

codes! {
    // Syntax (mission scripts).
    InvalidCharacter = "E001", Error, "a character that the language does not use";
    UnterminatedString = "E002", Error, "a string without its closing quote";
    SyntaxError = "E003", Error, "the text does not follow the grammar";
    TooManyProblems = "E004", Error, "more problems than are shown (the first 100 syntax problems and the first 200 of a file are; the file may not be what it claims to be)";
    // Names and structure.
    UnknownRobotType = "E010", Error, "a robot type that the catalog does not have";
    DuplicateTeam = "E011", Error, "a team declared twice";
    DuplicateRobot = "E012", Error, "a robot name used twice";
    DuplicateService = "E013", Error, "a composite service defined twice for the same team and plan";
    DuplicateMode = "E014", Error, "a mode defined twice for the same team";
    UnknownTeam = "E015", Error, "a service, mode or main of a team that is not declared";
    ServiceNotInPlan = "E016", Error, "`set` names a service that the plan does not have";
    UnknownMode = "E017", Error, "`case`, `catch` or `mode =` names a mode that is not defined";
    MissingDefault = "E018", Error, "a main block without `default: mode = ...`";
    ServiceNotProvided = "E019", Error, "a built-in service that some robot running the statement lacks";
    UnsatisfiableGroup = "E020", Error, "a group condition that no robot of the team meets";
    UnknownCommTeam = "E021", Error, "an unknown team in send, receive, publish or subscribe";
    WrongArgumentCount = "E022", Error, "a built-in service called with too many or too few arguments";
    WrongArgumentType = "E023", Error, "an argument whose type the service does not accept";
    UnknownService = "E024", Error, "a call to a service or function that does not exist";
    DuplicateFunction = "E025", Error, "a function defined twice";
    DuplicateMain = "E026", Error, "two main blocks for the same team";
    ReservedName = "E027", Error, "a reserved word used as a name";
    EmptyRobotGroup = "E028", Error, "`name[N]` with N less than one";
    RecursiveFunction = "E029", Error, "a function that calls itself (functions are inlined)";
    PlanSetTwice = "E030", Error, "a mode that sets the same plan twice";
    DuplicateCase = "E031", Error, "a main block with two cases for the same mode";
    DuplicateCatch = "E032", Error, "a case that catches the same event twice";
    ValueNotProvided = "E033", Error, "a robot value that some robot reading it lacks";
    InvalidPeriod = "E034", Error, "a period or timeout that is not positive";
    OrderingNotNumeric = "E035", Error, "`<`, `<=`, `>` or `>=` with an operand that is not a number (a word, a string, a text value)";
    ReceivedNotAValue = "E040", Error, "a receive or subscribe of a name that is not a value: neither `Team.VALUE`, `USER.VALUE` nor `VALUE`";
    WordIsAValue = "E041", Error, "a bare word where a word may stand that is also a value the robots read: write `\"WORD\"` for the word or `Team.WORD` for the value";
    StrategyPassesNothing = "E042", Error, "an actuator's or algorithm's parameter without a `value` whose name is no parameter of the strategy's actions nor of the service: its task would get nothing";
    CountedGroupMin = "E037", Error, "a counted group's `min` that is not a positive whole number";
    DuplicateCountedGroup = "E038", Error, "two counted groups of one statement with the same name";
    CountedGroupsTooLarge = "E039", Error, "counted groups whose minimums add up to more robots than run the statement: they can never all be met";
    CountedGroupMixed = "E043", Error, "a counted group (`group(Name, min = N)`) beside an `instance of`/`capable of` group or a `leader` arm in one statement, or a `leader` arm with a count";
    DuplicateParameter = "E044", Error, "a function, composite service or mode with two parameters of the same name";
    ParameterHidesName = "E045", Error, "a parameter (of a function, composite service or mode) or an action result named like a value robots read or a team variable (a result also like a parameter): where used the name would mean the parameter or the result, hiding the other";
    ModeArgumentCount = "E046", Error, "a mode entered (`mode = MOVE(kitchen)`) or a composite service set (`set(Action, Go(kitchen))`) with more or fewer arguments than its parameters, or with arguments it does not take";
    ResultsNotGiven = "E049", Error, "a call that binds names its service does not give back: more names than the service's results, a function's call (functions give nothing back), a result named twice in one list, robots running the call whose types give different results, or one name bound to results of different types";
    ModeCopiesPastLimit = "E048", Error, "modes entered with so many distinct lists of arguments that their copies would hold more than 65,536 `set`s and catches in all";
    ArgumentNotFixed = "E047", Error, "an argument of a mode entered or of a service set that is not known when the mission is written (a value robots read, a team variable, an expression): each list of arguments is a mode of its own";
    TooManyRobots = "E036", Error, "`name[N]` with N above 4096, or a mission with more than 4096 robots in all";
    // Catalog files (*.robot.xml).
    CatalogXml = "E050", Error, "a catalog file that is not well-formed XML";
    CatalogUnknownElement = "E051", Error, "an element that the catalog format does not have";
    CatalogMissingAttribute = "E052", Error, "a required attribute is missing";
    CatalogDuplicateType = "E053", Error, "a robot type (or alias) defined twice";
    CatalogUnknownValueType = "E054", Error, "a value or parameter type that does not exist";
    CatalogMissingGraph = "E055", Error, "a `graph=` file that does not exist";
    CatalogBadAttribute = "E056", Error, "an attribute value of the wrong form";
    CatalogUnknownAttribute = "W050", Warning, "an attribute that the catalog format does not have";
    // Task graphs (*.taskgraph.xml, SDF3 files).
    GraphXml = "E060", Error, "a task-graph file that is not well-formed XML";
    GraphUnknownElement = "E061", Error, "an element that the task-graph format does not have";
    GraphMissingAttribute = "E062", Error, "a required task-graph attribute is missing";
    GraphDuplicateName = "E063", Error, "a task, port, loop or library named twice";
    GraphUnknownEndpoint = "E064", Error, "a channel end that names no task or port";
    GraphBadAttribute = "E065", Error, "a task-graph attribute value of the wrong form";
    GraphPortDirection = "E066", Error, "a channel from an input port or into an output port";
    GraphPortTwoChannels = "E098", Error, "a port joined by more than one channel: a port is the end of one channel (SDF3 refuses it too)";
    Sdf3TwoDefaultProcessors = "W086", Warning, "an SDF3 actor with more than one processor marked `default=\"true\"`: which one gives its time is ambiguous (semo takes the first, `--sdf3-compat` the last as SDF3 does)";
    SubgraphUnreadable = "E067", Error, "a task's `subgraph` file that cannot be found or read";
    SubgraphHasErrors = "E068", Error, "a task's `subgraph` file that has errors of its own";
    SubgraphCycle = "E069", Error, "`subgraph` references that lead back to a file on the way (a → b → a), or nest too deep";
    GraphUnknownAttribute = "W060", Warning, "an attribute that the task-graph format does not have";
    BufferTooSmall = "W061", Warning, "a channel whose declared capacity is smaller than the schedule needs";
    InconsistentRates = "E070", Error, "sample rates that no repetition vector satisfies";
    Deadlock = "E071", Error, "a cycle without enough initial samples: one iteration cannot complete";
    RateOverflow = "E072", Error, "rates whose repetition vector does not fit in 64 bits";
    LoopBoundaryRate = "E073", Error, "a loop port whose outer and inner rates do not match the loop";
    DistributingOnConvergentLoop = "E074", Error, "a distributing input port on a C-type (convergent) loop";
    ExitTaskNotInLoop = "E075", Error, "a loop's exitTask that is not a task of its body";
    UnknownLibrary = "E076", Error, "a library port naming a library that is not declared";
    UnknownLibraryFunction = "E077", Error, "a call through a library port to a function the library lacks";
    SubgraphPortMismatch = "E078", Error, "a task's ports that do not match the open ports of its sub-graph (by name and direction)";
    SubgraphBoundaryRate = "E079", Error, "a task's port rates that do not carry exactly one iteration of its sub-graph";
    MulticastWithoutReader = "W062", Warning, "a multicast group that tasks write but none reads";
    MulticastWithoutWriter = "W063", Warning, "a multicast group that tasks read but none writes";
    DataflowInconsistent = "W070", Warning, "a mission line calling a service whose task graph has inconsistent sample rates";
    DataflowDeadlock = "W071", Warning, "a mission line calling a service whose task graph deadlocks";
    DataflowBufferTooSmall = "W072", Warning, "a mission line calling a service whose task graph has a channel smaller than its schedule needs";
    DataflowTooSlow = "W073", Warning, "a `repeat(P)` or `loop(P)` period shorter than the iteration period of a service graph called inside: the robot cannot keep up";
    DataflowLatencyExceeded = "W074", Warning, "a call of a service whose task graph takes longer from a task to another than the latency bound its catalog states (`<Latency>`)";
    DataflowLatencyUnchecked = "W075", Warning, "a latency bound (`<Latency>`) of a service's task graph that cannot be checked: an unknown task, no execution times, no path, or no latency (the reason is given)";
    // Strategy files (*.strategy.xml).
    StrategyXml = "E080", Error, "a strategy file that is not well-formed XML";
    StrategyRawLt = "E081", Error, "a plain `<` inside an attribute value, where XML needs `&lt;`";
    StrategyUnknownElement = "E082", Error, "an element that the strategy format does not have there";
    StrategyMissingAttribute = "E083", Error, "a required strategy attribute or element is missing";
    StrategyBadAttribute = "E084", Error, "a strategy attribute value of the wrong form";
    StrategyDuplicate = "E085", Error, "an actionId, parameter or strategy entry given twice";
    StrategyBadTransition = "E086", Error, "a transition that does not leave its own action, or goes to no action";
    StrategyInitialAction = "E087", Error, "an action machine without exactly one initial action";
    StrategyUnknownParameter = "E088", Error, "a condition naming a parameter that the service does not declare";
    StrategyUnknownTeam = "E089", Error, "a strategy for a team that the missions do not declare";
    StrategyRobotNotInTeam = "E090", Error, "a `TargetRobot` that is not a robot type of the strategy's team";
    StrategyServiceNotCalled = "E091", Error, "a strategy `Service` that the team does not call in that plan";
    StrategyUnknownCompositeService = "E092", Error, "a leader selection naming a composite service that the team lacks or that elects no leader";
    StrategyUnknownValue = "E093", Error, "a `Value` that the target robot type does not have";
    StrategyUnknownTask = "E094", Error, "a `srcTask` or `dstTask` that is not a task of the target robot type";
    StrategyServiceNotProvided = "E095", Error, "a strategy `Service` that the target robot type does not provide";
    StrategyUnknownAttribute = "W080", Warning, "an attribute that the strategy format does not have";
    UnreachableAction = "W081", Warning, "an action that cannot be reached from the initial action";
    NoFinalAction = "W082", Warning, "an action machine in which no final action can be reached: the service never ends";
    FinalWithTransitions = "E096", Error, "a final action with outgoing transitions: the service ends there, so they are never taken";
    // Every XML file (catalogs, task graphs, strategy files).
    XmlTooDeep = "E097", Error, "an XML file whose elements are nested more than 256 deep: reading stops at the element past the limit";
    UncoveredGuards = "W083", Warning, "an action whose transition conditions leave some values of the variable they compare uncovered: the action waits there for ever";
    GuardNeverHolds = "W084", Warning, "a transition condition that no value of its variable satisfies";
    OverlappingGuards = "W085", Warning, "two transitions of one action that can be taken at once: the machine is not deterministic";
    // Code generation (`semo build`).
    CodegenUnsupported = "E100", Error, "a construct that code generation does not support yet";
    OutputNameEscapes = "E101", Error, "a name that cannot become a file or C identifier of the generated code (it could write outside the output folder, or clashes with a generated task)";
    CodegenInternal = "E102", Error, "an internal error of refinement or code generation: something the checker should have excluded (please report it)";
    TargetUnsupported = "E103", Error, "a robot its target cannot run as written (the target `--target`, the project file or its robot type's platform in the catalog chose): on a board a robot whose service runs a task graph, a board's simulation without `--scenario`, or one whose scenario has link faults on the messages of a robot on its serial link";
    ServiceSubgraphUnusable = "E135", Error, "a service implemented by a task graph whose sub-graph references cannot be used (a file that cannot be read, has errors, leads back to itself or whose open ports do not match the task's): the service cannot run";
    // The project file (`semo.toml`).
    ProjectSyntax = "E110", Error, "a project file (`semo.toml`) that is not valid TOML";
    ProjectBadValue = "E111", Error, "a project-file value of the wrong type or form (a folder list that is not a list of strings, an unknown target or lint level, a format version this semo does not read)";
    ProjectErrorAllowed = "E112", Error, "`[lints]` lowering an error code: only warnings and hints can be allowed or made warnings (an `E` code may only be `deny`)";
    ProjectUnknownKey = "W110", Warning, "a key or table that the project file format does not have, a lint naming no diagnostic code, or a `[build.targets]` name that is no team or robot of the mission built";
    ProjectMissingPath = "W111", Warning, "a catalog, strategy or task-graph folder or a deployment file named in the project file that does not exist";
    SearchBounded = "W112", Warning, "without a project file, the search for the catalog and strategy files beside a mission stopped at its bound (too many entries): put a `semo.toml` at the project root";
    // Deployment files (`*.deploy.toml`, `semo build --deploy`, `semo deploy`).
    DeployInvalid = "E120", Error, "a deployment file that is not valid TOML or not of the deployment format (unknown key, wrong type, a certificate without its key, a robot without credentials the broker needs)";
    DeployUnknownName = "E121", Error, "a deployment file naming a robot or team that the mission does not have";
    DeployBadBroker = "E122", Error, "a broker address that is not `mqtt://HOST[:PORT]` or `mqtts://HOST[:PORT]`";
    DeployMissingFile = "E123", Error, "a deployment file naming a password, CA, certificate or key file that does not exist";
    DeployBadTlsFile = "E126", Error, "a deployment file naming a CA or client certificate file that holds no PEM certificate, or a key file that holds no PEM private key (or that cannot be read)";
    DeployUnwritableValue = "E127", Error, "a deployment value that the broker's files cannot carry as it is (a user name or a path of the broker's configuration with a control character such as a line break, a space at an end, or a user name with `:`): written, it would be read back as another value or another directive";
    // Group services (`<GroupService>` in a strategy's `<GroupingInfo>`).
    GroupServiceNotCalled = "E124", Error, "a `GroupService` naming a built-in service that the team does not call (in that plan): no robot would be in the group";
    GroupServiceDuplicate = "E125", Error, "a service declared a group service twice (for the same plan)";
    // Refinement of strategies into the robots' programs.
    BatteryPolicyNamesNoTask = "W130", Warning, "a battery policy's sensor or actuator that names no task of any robot of its team, or a policy that names none: it changes nothing";
    // The owner of a library's globally shared values (`<SharedOwner>` in a strategy's `<GroupingInfo>`).
    SharedOwnerUnknownLibrary = "E130", Error, "a `SharedOwner` naming a library task that is not its team's (`<Team>Shared`)";
    SharedOwnerUnknownRobot = "E131", Error, "a `SharedOwner` naming a robot that is not a robot of its team";
    SharedOwnerHoldsNone = "W131", Warning, "a `SharedOwner` naming a robot that holds none of the team's globally shared values (it runs none of the statements using them): it cannot own them, the team's leader does";
    // Warnings (mission scripts).
    EventNeverCaught = "W001", Warning, "an event that is thrown but no mode of its team catches";
    UnreachableMode = "W002", Warning, "a mode that cannot be reached from the default mode";
    ServiceNeverSet = "W003", Warning, "a composite service that no mode sets";
    ReceiveWithoutSend = "W004", Warning, "a receive or subscribe that no send or publish feeds";
    SendWithoutReceive = "W005", Warning, "a send or publish that nobody receives";
    AmbiguousGroup = "W006", Warning, "robots that meet several group conditions";
    UnknownAttribute = "W007", Warning, "an attribute that is neither a robot value nor a team variable";
    ConstantOutsideDomain = "W008", Warning, "a constant outside the value's domain";
    CatchNeverThrown = "W009", Hint, "a catch of an event that no service of the mode throws";
    FunctionNeverCalled = "W010", Warning, "a function that is never called";
    TeamWithoutMain = "W011", Warning, "a team without a main block: its robots do nothing";
    EmptyOthers = "W012", Warning, "an `others` block that no robot is left to run";
    CountedGroupsNoSpare = "W014", Hint, "counted groups whose minimums take every robot that runs the statement: a robot lost leaves a group short";
    ParameterNeverUsed = "W015", Warning, "a parameter that is never used (a function's or a composite service's in its body, a mode's in its `set`s): its argument is given for nothing";
    ResultReadBeforeBound = "W016", Warning, "an action result read where no call written before it binds the name: until a call binding it is done, it is none";
    BroadcastToNoOne = "W013", Hint, "a `throw E broadcast` that only one robot runs: its group (or team) has no one else to tell";
    ComparisonNeverHolds = "W020", Warning, "a comparison of a team variable or a parameter with a value it is never given: it never holds";
    ComparisonAlwaysHolds = "W021", Warning, "`!=` between a team variable or a parameter and a value it is never given: it always holds (a variable, once it has a value)";
    ReadBeforeSent = "W022", Warning, "a value read once, when the mission starts, before any robot can have sent it: it reads none, and nothing sent later is read there";
    ForwardedOnce = "W023", Warning, "a received value sent on once each time its mode starts while another plan of the mode keeps receiving it: what comes later is never sent on";
    ReceiveNeverFed = "W024", Warning, "a receive or subscribe that no robot can ever feed: its sends or publishes never run, or run only on the receiving robot itself";
    ModeNeverEntered = "V001", Warning, "`semo verify`: a mode no robot of its team enters in any behaviour";
    NeverFinishes = "V002", Warning, "`semo verify`: a robot that finishes in some behaviours can reach a state from which it never finishes";
    WaitsForEver = "V003", Warning, "`semo verify`: a robot can reach a `receive` where it waits for ever, whatever the world does";
    TwoLeaders = "V004", Warning, "`semo verify`: two robots can lead one `leader(...)` statement at once (with faults: a robot killed, restarted or cut off, messages lost)";
    PlansRace = "V005", Warning, "`semo verify`: a plan's `throw` ends its mode in the instant another plan of the mode would send or throw: which one happens depends only on the plans' order";
    RobotsRace = "V006", Warning, "`semo verify`: a robot takes messages of two robots in one instant, and taken in the other order (which the network may give) it would react otherwise: which message comes first decides (a race between robots)";
}

impl fmt::Display for Code {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

/// A secondary location that explains a diagnostic ("first defined here").
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Related {
    pub file: FileId,
    pub span: Span,
    pub message: String,
}

/// One finding, positioned by byte range in `file`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Diagnostic {
    pub code: Code,
    pub severity: Severity,
    pub file: FileId,
    pub span: Span,
    pub message: String,
    /// The replacement the user most likely meant (did-you-mean), if any.
    pub suggestion: Option<String>,
    pub related: Vec<Related>,
}

/// Messages are one line (renderers and editors rely on it), but they quote
/// names the user wrote, which may hold line breaks (an XML attribute value).
fn one_line(message: String) -> String {
    if !message.contains(['\n', '\r']) {
        return message;
    }
    message.replace('\r', "\\r").replace('\n', "\\n")
}

impl Diagnostic {
    pub fn new(code: Code, file: FileId, span: Span, message: impl Into<String>) -> Self {
        Diagnostic {
            code,
            severity: code.default_severity(),
            file,
            span,
            message: one_line(message.into()),
            suggestion: None,
            related: Vec::new(),
        }
    }

    /// Adds a did-you-mean: the message gains "(did you mean `x`?)".
    pub fn suggest(&mut self, suggestion: Option<String>) -> &mut Self {
        if let Some(s) = &suggestion {
            self.message = format!("{} (did you mean `{s}`?)", self.message);
        }
        self.suggestion = suggestion;
        self
    }

    /// Adds a secondary location, such as "first defined here".
    pub fn relate(&mut self, span: Span, message: impl Into<String>) -> &mut Self {
        self.related.push(Related {
            file: self.file,
            span,
            message: message.into(),
        });
        self
    }

    pub fn with_severity(mut self, severity: Severity) -> Self {
        self.severity = severity;
        self
    }

    pub fn is_error(&self) -> bool {
        self.severity == Severity::Error
    }
}

/// Where a loader or checker puts what it finds, in the order found: the one
/// `report` every pass uses (each used to carry its own copy). It is the
/// list of diagnostics (it dereferences to it), with the file reported on.
#[derive(Debug)]
pub struct Sink {
    file: FileId,
    /// XML readers quote attribute values: their control characters become
    /// spaces (as [`Sink::quoting_xml`] says), beyond the line breaks every
    /// message escapes.
    control_as_space: bool,
    list: Vec<Diagnostic>,
}

impl Sink {
    pub fn new(file: FileId) -> Sink {
        Sink {
            file,
            control_as_space: false,
            list: Vec::new(),
        }
    }

    /// A sink whose messages have every control character as a space: for
    /// the XML readers, whose messages quote attribute values.
    pub fn quoting_xml(file: FileId) -> Sink {
        Sink {
            control_as_space: true,
            ..Sink::new(file)
        }
    }

    pub fn file(&self) -> FileId {
        self.file
    }

    /// Reports `message` at `span` of the sink's file; the diagnostic can be
    /// refined (a did-you-mean, related places).
    pub fn report(
        &mut self,
        code: Code,
        span: Span,
        message: impl Into<String>,
    ) -> &mut Diagnostic {
        self.report_in(code, self.file, span, message)
    }

    /// Reports in another file (a cross-check finding a mission line).
    pub fn report_in(
        &mut self,
        code: Code,
        file: FileId,
        span: Span,
        message: impl Into<String>,
    ) -> &mut Diagnostic {
        let mut message: String = message.into();
        if self.control_as_space {
            message = message
                .chars()
                .map(|c| if c.is_control() { ' ' } else { c })
                .collect();
        }
        push(&mut self.list, Diagnostic::new(code, file, span, message))
    }

    pub fn into_vec(self) -> Vec<Diagnostic> {
        self.list
    }
}

/// Adds `diagnostic` to `list` and gives it back to be refined: what
/// [`Sink::report_in`] does, for a pass whose findings have no one file (the
/// strategy cross-check).
pub fn push(list: &mut Vec<Diagnostic>, diagnostic: Diagnostic) -> &mut Diagnostic {
    list.push(diagnostic);
    let last = list.len() - 1;
    &mut list[last]
}

impl std::ops::Deref for Sink {
    type Target = Vec<Diagnostic>;

    fn deref(&self) -> &Vec<Diagnostic> {
        &self.list
    }
}

impl std::ops::DerefMut for Sink {
    fn deref_mut(&mut self) -> &mut Vec<Diagnostic> {
        &mut self.list
    }
}

/// Sort diagnostics by file and position, and drop exact repeats (a function body
/// checked at several call sites reports the same finding once).
pub fn sort_and_dedup(diags: &mut Vec<Diagnostic>) {
    diags.sort_by(|a, b| {
        (a.file, a.span.start, a.span.end, a.code).cmp(&(b.file, b.span.start, b.span.end, b.code))
    });
    diags.dedup_by(|a, b| {
        a.file == b.file && a.span == b.span && a.code == b.code && a.message == b.message
    });
}

/// The most diagnostics reported for one file, whatever found them (syntax,
/// checker, loaders, cross-checks): past them the file is more likely junk
/// than work in progress, and every further one costs the renderer and the
/// editor time and memory without telling the user anything new.
pub const MAX_PER_FILE: usize = 200;

/// Keeps the first [`MAX_PER_FILE`] of one file's sorted diagnostics and, if
/// there were more, adds one E004 at the first one left out saying how many.
pub fn cap_per_file(diags: &mut Vec<Diagnostic>) {
    if diags.len() <= MAX_PER_FILE {
        return;
    }
    let hidden = diags.len() - MAX_PER_FILE;
    let first_hidden = &diags[MAX_PER_FILE];
    let note = Diagnostic::new(
        Code::TooManyProblems,
        first_hidden.file,
        first_hidden.span,
        format!(
            "{hidden} more problem(s) in this file from here on are not shown \
             (the first {MAX_PER_FILE} are): fix the ones above first"
        ),
    );
    diags.truncate(MAX_PER_FILE);
    diags.push(note);
}

#[cfg(test)]
mod cap_tests {
    use super::*;

    fn at(start: usize) -> Diagnostic {
        Diagnostic::new(
            Code::UnknownTeam,
            FileId(3),
            Span::new(start, start + 1),
            "x",
        )
    }

    #[test]
    fn a_file_with_few_diagnostics_keeps_them_all() {
        let mut diags: Vec<Diagnostic> = (0..MAX_PER_FILE).map(at).collect();
        cap_per_file(&mut diags);
        assert_eq!(diags.len(), MAX_PER_FILE);
        assert!(diags.iter().all(|d| d.code == Code::UnknownTeam));
    }

    #[test]
    fn past_the_cap_one_e004_says_how_many_more_and_where_they_start() {
        let mut diags: Vec<Diagnostic> = (0..MAX_PER_FILE + 57).map(at).collect();
        cap_per_file(&mut diags);
        assert_eq!(diags.len(), MAX_PER_FILE + 1);
        let note = diags.last().unwrap();
        assert_eq!(note.code, Code::TooManyProblems);
        assert_eq!(note.file, FileId(3));
        assert_eq!(note.span, Span::new(MAX_PER_FILE, MAX_PER_FILE + 1));
        assert!(
            note.message.starts_with("57 more problem(s)"),
            "{}",
            note.message
        );
    }
}
