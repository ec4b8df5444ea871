//! The strategy model: how one team performs the services of a mission (the
//! format: `docs/strategy.md`). Every entry keeps the byte ranges it was read
//! from, so that checks (and the language server) can point into the file.
//!
//! Entries are kept even when an attribute is missing or malformed (that is
//! reported by the loader): the field is then `None`, and the rest of the entry
//! is still checked.

use crate::diag::FileId;
use crate::span::Span;
use crate::syntax::ast;

/// An enum of the words an attribute or element name may be, each written
/// once: `ALL` (word, value) for reading, and the method named after `by` for
/// the word of a value.
macro_rules! words {
    (
        $(#[$meta:meta])*
        pub enum $name:ident, by $word_of:ident {
            $($(#[$variant_meta:meta])* $variant:ident = $word:literal,)*
        }
    ) => {
        $(#[$meta])*
        #[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
        pub enum $name {
            $($(#[$variant_meta])* $variant,)*
        }

        impl $name {
            pub const ALL: [(&'static str, $name); [$($word),*].len()] =
                [$(($word, $name::$variant)),*];

            pub fn $word_of(self) -> &'static str {
                match self {
                    $($name::$variant => $word,)*
                }
            }
        }
    };
}

/// A name or word as written in an attribute, trimmed, with its range.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Named {
    pub name: String,
    pub span: Span,
}

/// One `*.strategy.xml` file: `<Strategy name="Team">`.
#[derive(Clone, Debug, PartialEq)]
pub struct Strategy {
    pub file: FileId,
    /// The team the strategy is for (`name`).
    pub team: Option<Named>,
    /// The `<Strategy>` start tag.
    pub tag: Span,
    /// `<ValueInfo>`: where mission values come from.
    pub values: Vec<ValueEntry>,
    /// `<ServiceInfo>`: services refined into action machines.
    pub services: Vec<ServiceEntry>,
    /// `<GroupingInfo>`.
    pub grouping: Option<Grouping>,
    /// `<NonFunctionalInfo>`: each `<Condition>` of each `<BatteryRequirement>`.
    pub battery_rules: Vec<BatteryRule>,
}

/// `<TargetRobot name="iRobotCreate" nickName="irobot" ea="1"/>`.
#[derive(Clone, Debug, PartialEq)]
pub struct TargetRobot {
    /// The robot type.
    pub name: Option<Named>,
    pub nick_name: Option<Named>,
    /// `ea`, kept as written (the thesis's files carry it; its meaning is not
    /// specified).
    pub ea: Option<Named>,
    pub span: Span,
}

/// `<Value name="DISTANCE">`: binds a mission value to sensor or algorithm
/// tasks on the target robot types.
#[derive(Clone, Debug, PartialEq)]
pub struct ValueEntry {
    pub name: Option<Named>,
    pub targets: Vec<TargetRobot>,
    pub tasks: Vec<TaskUse>,
    /// The whole element.
    pub span: Span,
    /// The start tag.
    pub tag: Span,
}

words! {
    /// Which kind of task an action (or value) uses.
    pub enum TaskUseKind, by tag {
        /// `<CheckSensor>`: read a sensor task.
        CheckSensor = "CheckSensor",
        /// `<ExecuteActuator>`: drive an actuator task.
        ExecuteActuator = "ExecuteActuator",
        /// `<ExecuteAlgorithm>`: run an algorithm task.
        ExecuteAlgorithm = "ExecuteAlgorithm",
    }
}

/// `<CheckSensor name="Vicon">` (or actuator, algorithm) with its parameters.
#[derive(Clone, Debug, PartialEq)]
pub struct TaskUse {
    pub kind: TaskUseKind,
    pub name: Option<Named>,
    pub parameters: Vec<Parameter>,
    pub span: Span,
}

words! {
    /// `dataCharacteristic`: how a parameter's data moves.
    pub enum DataCharacteristic, by as_str {
        /// A FIFO channel from or to a task (`srcTask` → `dstTask`).
        Channel = "channel",
        /// A variable local to the control task.
        Variable = "variable",
        /// A task parameter set through the runtime, then the task is called.
        SysRequest = "sysRequest",
    }
}

/// `<Parameter name="distance" type="integer" dataCharacteristic="channel"
/// size="1" srcTask="ultrasonic" dstTask="ControlTask"/>`.
#[derive(Clone, Debug, PartialEq)]
pub struct Parameter {
    pub name: Option<Named>,
    /// The data type as written (`integer`, `viconInfo`): a C-level type of
    /// the task code, not a mission value type.
    pub ty: Option<Named>,
    pub data: Option<DataCharacteristic>,
    pub size: Option<u64>,
    /// `value`: the initial value or the request sent, as written.
    pub value: Option<Named>,
    pub src_task: Option<Named>,
    pub dst_task: Option<Named>,
    pub span: Span,
}

/// `<Service plan_name="Action" name="move">`: a built-in service of one plan,
/// for the listed robot types, refined into a state machine of actions.
#[derive(Clone, Debug, PartialEq)]
pub struct ServiceEntry {
    pub plan: Option<Named>,
    /// `name` (or its alias `service_name`): the built-in service.
    pub name: Option<Named>,
    pub targets: Vec<TargetRobot>,
    /// The actions of `<ActionInfo>`, in file order.
    pub actions: Vec<Action>,
    pub span: Span,
    pub tag: Span,
    /// False when malformed XML cut the entry short: its action machine is
    /// not checked as a whole.
    pub complete: bool,
}

impl ServiceEntry {
    /// Every parameter the service declares (in any action, directly or in a
    /// task use), action by action: the names its conditions may read.
    pub fn parameters(&self) -> impl Iterator<Item = &Parameter> {
        self.actions.iter().flat_map(Action::parameters)
    }

    /// Whether `name` is a parameter the entry's conditions and commands read
    /// by name: a sensor reading (a `CheckSensor`'s), or an action's own
    /// variable (set from the call's argument in its position) or fixed
    /// value.
    pub fn reads(&self, name: &str) -> bool {
        self.actions.iter().any(|action| {
            let sensed = action
                .tasks
                .iter()
                .filter(|t| t.kind == TaskUseKind::CheckSensor)
                .flat_map(|t| &t.parameters);
            let own = action
                .parameters
                .iter()
                .filter(|p| p.value.is_some() || p.data == Some(DataCharacteristic::Variable));
            sensed
                .chain(own)
                .any(|p| p.name.as_ref().is_some_and(|n| n.name == name))
        })
    }

    /// What a parameter of an `ExecuteActuator` or `ExecuteAlgorithm` of this
    /// entry passes to its task: its `value`, else its own name, read as a
    /// parameter of the entry ([`ServiceEntry::reads`]), else as one of the
    /// refined service's (`service_params`, the catalog's, in order: the
    /// call's argument in that position), else (a `value` only) as written.
    pub fn passed<'p>(&self, parameter: &'p Parameter, service_params: &[&str]) -> Passed<'p> {
        let Some(said) = parameter.value.as_ref().or(parameter.name.as_ref()) else {
            return Passed::Nothing;
        };
        let said = said.name.as_str();
        if self.reads(said) {
            Passed::Named(said)
        } else if let Some(index) = service_params.iter().position(|p| *p == said) {
            Passed::Argument(index)
        } else if parameter.value.is_some() {
            Passed::Literal(said)
        } else {
            Passed::Nothing
        }
    }

    /// The action whose `actionId` is `id` (the first one, if given twice).
    pub fn action_by_id(&self, id: u64) -> Option<&Action> {
        self.actions
            .iter()
            .find(|a| a.id.as_ref().is_some_and(|i| i.value == id))
    }
}

/// What a task use's parameter passes to its task ([`ServiceEntry::passed`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Passed<'p> {
    /// The entry's parameter of this name (a sensor reading, a variable, a
    /// fixed value).
    Named(&'p str),
    /// The call's argument in this position.
    Argument(usize),
    /// The `value` as written: a word or a number.
    Literal(&'p str),
    /// No `value`, and its name is no parameter of the entry nor of the
    /// service (E042).
    Nothing,
}

/// An `actionId`, `srcId` or `dstId` with its range.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ActionId {
    pub value: u64,
    pub span: Span,
}

/// `<Action name="CheckGoal" initial="Yes" actionId="0">`.
#[derive(Clone, Debug, PartialEq)]
pub struct Action {
    pub name: Option<Named>,
    pub id: Option<ActionId>,
    /// `initial`: the action the service starts with.
    pub initial: YesNo,
    /// `final`: the service ends when this action is done.
    pub is_final: YesNo,
    pub tasks: Vec<TaskUse>,
    /// `<Parameter>`s directly inside the action (variables).
    pub parameters: Vec<Parameter>,
    pub transitions: Vec<Transition>,
    pub span: Span,
    pub tag: Span,
}

impl Action {
    /// The action's own parameters, then those of its task uses.
    pub fn parameters(&self) -> impl Iterator<Item = &Parameter> {
        self.parameters
            .iter()
            .chain(self.tasks.iter().flat_map(|t| t.parameters.iter()))
    }

    /// `name (actionId)` for messages.
    pub fn describe(&self) -> String {
        match (&self.name, &self.id) {
            (Some(n), Some(id)) => format!("`{}` ({})", n.name, id.value),
            (Some(n), None) => format!("`{}`", n.name),
            (None, Some(id)) => format!("action {}", id.value),
            (None, None) => "this action".to_string(),
        }
    }
}

/// An `initial` or `final` attribute.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum YesNo {
    /// `No`, or not given.
    No,
    /// `Yes`, with the value's range.
    Yes(Span),
    /// Neither `Yes` nor `No` (reported): checks that depend on it say nothing.
    Malformed(Span),
}

impl YesNo {
    pub fn is_yes(self) -> bool {
        matches!(self, YesNo::Yes(_))
    }

    pub fn is_malformed(self) -> bool {
        matches!(self, YesNo::Malformed(_))
    }

    /// The value's range when given as `Yes` (or malformed).
    pub fn span(self) -> Option<Span> {
        match self {
            YesNo::No => None,
            YesNo::Yes(span) | YesNo::Malformed(span) => Some(span),
        }
    }
}

/// `<Transition srcId="0" dstId="4"><Condition cond="..."/></Transition>`.
#[derive(Clone, Debug, PartialEq)]
pub struct Transition {
    pub src: Option<ActionId>,
    pub dst: Option<ActionId>,
    /// `None`: always taken.
    pub condition: Option<Condition>,
    pub span: Span,
}

/// A `cond="..."` attribute, parsed with the mission expression grammar.
#[derive(Clone, Debug, PartialEq)]
pub struct Condition {
    /// The condition with entities replaced (`distance<=20`).
    pub text: String,
    /// The range of the attribute value.
    pub span: Span,
    /// `None` when it did not parse (reported).
    pub expr: Option<ast::Expr>,
}

/// `<GroupingInfo>`.
#[derive(Clone, Debug, PartialEq)]
pub struct Grouping {
    pub leader_selection: Option<LeaderSelection>,
    /// `<GroupSync timeout="5 SEC"/>`: how long the robots of a group wait for
    /// each other at the start of a group statement.
    pub sync_timeout: Option<Duration>,
    /// `<GroupService name="search"/>`s, in file order.
    pub group_services: Vec<GroupService>,
    /// `<SharedOwner library="ScoutsShared" robot="b"/>`: the robot that
    /// owns the library's globally shared values at start.
    pub shared_owner: Option<SharedOwner>,
    pub span: Span,
}

/// `<SharedOwner library="ScoutsShared" robot="b"/>`: robot `robot` of the
/// team owns the globally shared values of its library task (`<Team>Shared`)
/// at start; when it is lost, the next robot of the formation order that
/// lives does (`docs/shared-information.md`). Without it the team's leader
/// owns them.
#[derive(Clone, Debug, PartialEq)]
pub struct SharedOwner {
    pub library: Option<Named>,
    pub robot: Option<Named>,
    pub span: Span,
}

/// `<GroupService name="search" plan_name="Explore"/>`: the built-in service
/// `name` (called in plan `plan_name`, or in any plan without it) is a group
/// service. The robots of the team that run any of its group services form
/// the team's group: each live member learns its rank among the live members
/// and their number (`semo_group_rank()`, `semo_group_size()`), recomputed
/// when a member fails or returns (`docs/groups.md`, "Group services").
#[derive(Clone, Debug, PartialEq)]
pub struct GroupService {
    /// The built-in service, as the catalog or the mission names it.
    pub name: Option<Named>,
    pub plan: Option<Named>,
    pub span: Span,
}

words! {
    /// The leader-selection algorithms.
    pub enum LeaderAlgorithm, by as_str {
        LowestId = "lowest_id",
        HighestBattery = "highest_battery",
        Bully = "bully",
    }
}

/// `<LeaderSelectionInfo algorithm="lowest_id" heartbeatPeriod="1 SEC"
/// plan_name="Resolve" cs_name="Decide"/>`. With `plan_name` and `cs_name`, it
/// applies to the leader elections of that composite service.
#[derive(Clone, Debug, PartialEq)]
pub struct LeaderSelection {
    pub algorithm: Option<LeaderAlgorithm>,
    pub heartbeat: Option<Duration>,
    pub plan: Option<Named>,
    /// `cs_name`: the composite service.
    pub service: Option<Named>,
    pub span: Span,
}

/// A period such as `1 SEC`, in milliseconds.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Duration {
    pub millis: f64,
    pub span: Span,
}

/// One `<Condition cond="Battery&lt;30">` of a `<BatteryRequirement>`: while
/// it holds, the listed sensors and actuators run at the given levels.
#[derive(Clone, Debug, PartialEq)]
pub struct BatteryRule {
    pub condition: Option<Condition>,
    /// `<Sensor name="Camera" periodLevel="2"/>`.
    pub sensors: Vec<LevelSetting>,
    /// `<Actuator name="Move" speedLevel="2"/>`.
    pub actuators: Vec<LevelSetting>,
    pub span: Span,
}

/// A sensor's `periodLevel` or an actuator's `speedLevel`.
#[derive(Clone, Debug, PartialEq)]
pub struct LevelSetting {
    pub name: Option<Named>,
    pub level: Option<u64>,
    pub span: Span,
}
