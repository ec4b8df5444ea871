//! The strategy format's vocabulary, written once: which attributes each
//! element has (read by the loader) and which children it may hold, with the
//! short descriptions the editor shows. `docs/strategy.md` is the format's
//! reference for users (`compiler/tests/format_docs.rs` checks that it names
//! every element and attribute here); the descriptions say the same in brief.

pub(crate) const STRATEGY_ATTRS: &[&str] = &["name"];
pub(crate) const VALUE_ATTRS: &[&str] = &["name"];
pub(crate) const SERVICE_ATTRS: &[&str] = &["plan_name", "name", "service_name"];
pub(crate) const TARGET_ATTRS: &[&str] = &["name", "nickName", "ea"];
pub(crate) const TASK_USE_ATTRS: &[&str] = &["name"];
pub(crate) const PARAMETER_ATTRS: &[&str] = &[
    "name",
    "type",
    "dataCharacteristic",
    "size",
    "value",
    "srcTask",
    "dstTask",
];
pub(crate) const ACTION_ATTRS: &[&str] = &["name", "actionId", "initial", "final"];
pub(crate) const TRANSITION_ATTRS: &[&str] = &["srcId", "dstId"];
pub(crate) const CONDITION_ATTRS: &[&str] = &["cond"];
pub(crate) const LEADER_ATTRS: &[&str] = &["algorithm", "heartbeatPeriod", "plan_name", "cs_name"];
pub(crate) const SYNC_ATTRS: &[&str] = &["timeout"];
pub(crate) const GROUP_SERVICE_ATTRS: &[&str] = &["name", "plan_name"];
pub(crate) const SHARED_OWNER_ATTRS: &[&str] = &["library", "robot"];
pub(crate) const SENSOR_ATTRS: &[&str] = &["name", "periodLevel"];
pub(crate) const ACTUATOR_ATTRS: &[&str] = &["name", "speedLevel"];

/// One element of the format.
pub struct ElementInfo {
    pub name: &'static str,
    pub attributes: &'static [&'static str],
    /// Attributes without which the loader reports E083.
    pub required: &'static [&'static str],
    pub doc: &'static str,
}

const fn element(
    name: &'static str,
    attributes: &'static [&'static str],
    required: &'static [&'static str],
    doc: &'static str,
) -> ElementInfo {
    ElementInfo {
        name,
        attributes,
        required,
        doc,
    }
}

pub const ELEMENTS: &[ElementInfo] = &[
    element(
        "Strategy",
        STRATEGY_ATTRS,
        &["name"],
        "How one team's robots perform the services of a mission. `name` is the team.",
    ),
    element(
        "ValueInfo",
        &[],
        &[],
        "Where mission values come from: each `<Value>` binds a value to a sensor or algorithm task, per robot type.",
    ),
    element(
        "ServiceInfo",
        &[],
        &[],
        "The built-in services the team's composite services call, each refined into a state machine of actions.",
    ),
    element(
        "GroupingInfo",
        &[],
        &[],
        "How groups form: the leader-selection algorithm, the synchronization timeout at the start of a group, and the group services.",
    ),
    element(
        "NonFunctionalInfo",
        &[],
        &[],
        "Adaptive resource management: when a condition on `Battery` holds, lower sensor period levels or actuator speed levels.",
    ),
    element(
        "Value",
        VALUE_ATTRS,
        &["name"],
        "Binds a mission value to a sensor (`CheckSensor`) or algorithm (`ExecuteAlgorithm`) task on the target robot types; the refinement adds that task and a channel to the control task.",
    ),
    element(
        "Service",
        SERVICE_ATTRS,
        &["plan_name", "name"],
        "Refines one built-in service, as called in one plan, for the listed robot types, into a state machine of actions (the bottom level of the control task's FSM).",
    ),
    element(
        "TargetRobot",
        TARGET_ATTRS,
        &["name"],
        "A robot type this entry is for (a robot type of the strategy's team).",
    ),
    element(
        "CheckSensor",
        TASK_USE_ATTRS,
        &["name"],
        "Reads a sensor task; its `<Parameter>`s are the data read.",
    ),
    element(
        "ExecuteActuator",
        TASK_USE_ATTRS,
        &["name"],
        "Drives an actuator task; its `<Parameter>`s are the commands sent.",
    ),
    element(
        "ExecuteAlgorithm",
        TASK_USE_ATTRS,
        &["name"],
        "Runs an algorithm task; its `<Parameter>`s are its inputs and outputs.",
    ),
    element(
        "Parameter",
        PARAMETER_ATTRS,
        &["name", "type", "dataCharacteristic"],
        "Data of an action: from or to a task (`channel`, `sysRequest`) or local to the control task (`variable`). Conditions read parameters by name.",
    ),
    element(
        "ActionInfo",
        &[],
        &[],
        "The actions of the service's state machine: exactly one `initial=\"Yes\"`, and a reachable `final=\"Yes\"` one.",
    ),
    element(
        "Action",
        ACTION_ATTRS,
        &["name", "actionId"],
        "One state of the service's machine: reads sensors, drives actuators, runs algorithms, holds variables, then follows the first transition whose condition holds.",
    ),
    element(
        "TransitionInfo",
        &[],
        &[],
        "The transitions leaving the enclosing action.",
    ),
    element(
        "Transition",
        TRANSITION_ATTRS,
        &["srcId", "dstId"],
        "From the enclosing action (`srcId`) to another (`dstId`), guarded by a `<Condition>`; none means always.",
    ),
    element(
        "Condition",
        CONDITION_ATTRS,
        &["cond"],
        "A guard over the service's parameters (in a transition), or over `Battery` (in a battery requirement), in the mission's expression syntax. Write `<` as `&lt;`.",
    ),
    element(
        "LeaderSelectionInfo",
        LEADER_ATTRS,
        &["algorithm"],
        "The leader-selection algorithm and its heartbeat period; with `plan_name` and `cs_name`, for the leader elections of that composite service.",
    ),
    element(
        "GroupSync",
        SYNC_ATTRS,
        &["timeout"],
        "How long the robots of a group wait for each other at the start of a group statement.",
    ),
    element(
        "GroupService",
        GROUP_SERVICE_ATTRS,
        &["name"],
        "A group service: the robots of the team that run it form the team's group; each live member learns its rank and the number of live members (`semo_group_rank()`, `semo_group_size()`), recomputed when a member fails or returns.",
    ),
    element(
        "SharedOwner",
        SHARED_OWNER_ATTRS,
        &["library", "robot"],
        "The robot that owns the library task's globally shared values at start (the next live robot in formation order when it is lost); without it the team's leader owns them.",
    ),
    element(
        "BatteryRequirement",
        &[],
        &[],
        "A policy applied by the generated resource manager while the battery is low.",
    ),
    element(
        "Sensor",
        SENSOR_ATTRS,
        &["name", "periodLevel"],
        "While the condition holds, run this sensor at a lower period level.",
    ),
    element(
        "Actuator",
        ACTUATOR_ATTRS,
        &["name", "speedLevel"],
        "While the condition holds, drive this actuator at a lower speed level.",
    ),
];

pub fn element_info(name: &str) -> Option<&'static ElementInfo> {
    ELEMENTS.iter().find(|e| e.name == name)
}

/// The elements allowed inside `parent` (itself inside `grandparent`: a
/// `<Condition>` holds sensors and actuators only in a battery requirement);
/// `None` is the top of the file.
pub fn children(parent: Option<&str>, grandparent: Option<&str>) -> &'static [&'static str] {
    match parent {
        None => &["Strategy"],
        Some("Strategy") => &[
            "ValueInfo",
            "ServiceInfo",
            "GroupingInfo",
            "NonFunctionalInfo",
        ],
        Some("ValueInfo") => &["Value"],
        Some("Value") => &["TargetRobot", "CheckSensor", "ExecuteAlgorithm"],
        Some("ServiceInfo") => &["Service"],
        Some("Service") => &["TargetRobot", "ActionInfo"],
        Some("ActionInfo") => &["Action"],
        Some("Action") => &[
            "CheckSensor",
            "ExecuteActuator",
            "ExecuteAlgorithm",
            "Parameter",
            "TransitionInfo",
        ],
        Some("CheckSensor" | "ExecuteActuator" | "ExecuteAlgorithm") => &["Parameter"],
        Some("TransitionInfo") => &["Transition"],
        Some("Transition") => &["Condition"],
        Some("GroupingInfo") => &[
            "LeaderSelectionInfo",
            "GroupSync",
            "GroupService",
            "SharedOwner",
        ],
        Some("NonFunctionalInfo") => &["BatteryRequirement"],
        Some("BatteryRequirement") => &["Condition"],
        Some("Condition") if grandparent == Some("BatteryRequirement") => &["Sensor", "Actuator"],
        Some(_) => &[],
    }
}

/// What an attribute of `element` means.
pub fn attribute_doc(element: &str, attribute: &str) -> Option<&'static str> {
    Some(match (element, attribute) {
        ("Strategy", "name") => {
            "The team this strategy is for (a team of the workspace's missions)."
        }
        ("Value", "name") => {
            "The mission value (a catalog value of the target robot types), e.g. `DISTANCE`."
        }
        ("Service", "plan_name") => "The plan whose composite services call the service.",
        ("Service", "name" | "service_name") => {
            "The built-in service refined (called by the team's composite services in that plan); `service_name` is an alias."
        }
        ("TargetRobot", "name") => "A robot type of the strategy's team.",
        ("TargetRobot", "nickName") => "The robot's name in the mission (optional).",
        ("TargetRobot", "ea") => {
            "Kept as written (the original files carry it; its meaning is not specified)."
        }
        ("CheckSensor", "name") => "The sensor read.",
        ("ExecuteActuator", "name") => "The actuator driven.",
        ("ExecuteAlgorithm", "name") => "The algorithm run.",
        ("Parameter", "name") => "The parameter's name, read by conditions.",
        ("Parameter", "type") => {
            "The data type in the task code (`integer`, `viconInfo`), not a mission value type."
        }
        ("Parameter", "dataCharacteristic") => {
            "How the data moves: `channel` (a FIFO from/to a task), `variable` (local to the control task), `sysRequest` (a task parameter set through the runtime, then the task is called)."
        }
        ("Parameter", "size") => "How many samples (at least 1).",
        ("Parameter", "value") => "The initial value, or the request sent.",
        ("Parameter", "srcTask") => {
            "The task the data comes from (`ControlTask` or a task of the target robot type)."
        }
        ("Parameter", "dstTask") => {
            "The task the data goes to (`ControlTask` or a task of the target robot type)."
        }
        ("Action", "name") => "The action's name.",
        ("Action", "actionId") => {
            "The action's number, unique in the service; transitions name actions by it."
        }
        ("Action", "initial") => "`Yes`: the service starts with this action (exactly one action).",
        ("Action", "final") => "`Yes`: the service ends when this action is done.",
        ("Transition", "srcId") => "The enclosing action's `actionId`.",
        ("Transition", "dstId") => "The `actionId` of the action that follows.",
        ("Condition", "cond") => {
            "The guard, in the mission's expression syntax; write `<` as `&lt;`."
        }
        ("LeaderSelectionInfo", "algorithm") => "`lowest_id`, `highest_battery` or `bully`.",
        ("LeaderSelectionInfo", "heartbeatPeriod") => {
            "How often the leader says it is alive, e.g. `1 SEC`."
        }
        ("LeaderSelectionInfo", "plan_name") => {
            "The plan of the composite service whose leader elections this applies to."
        }
        ("LeaderSelectionInfo", "cs_name") => {
            "The composite service (with a `[[ leader(...) ... ]]` statement)."
        }
        ("GroupSync", "timeout") => {
            "How long the robots of a group wait for each other, e.g. `5 SEC`."
        }
        ("GroupService", "name") => {
            "The built-in service whose robots form the team's group (e.g. `search`)."
        }
        ("GroupService", "plan_name") => {
            "The plan whose calls of the service count; without it, calls in any plan."
        }
        ("SharedOwner", "library") => {
            "The team's library task, `<Team>Shared` (e.g. `ScoutsShared`), whose globally shared values the robot owns."
        }
        ("SharedOwner", "robot") => {
            "The robot of the team (its name in the mission, e.g. `b` or `tb_1`) that owns them at start."
        }
        ("Sensor", "name") => "The sensor whose period is lowered.",
        ("Sensor", "periodLevel") => {
            "The period level while the condition holds (1 or more): the sensor samples every period × level; 1 is its own period."
        }
        ("Actuator", "name") => "The actuator whose speed is lowered.",
        ("Actuator", "speedLevel") => {
            "The speed level while the condition holds (1 or more): the actuator runs at 1/level of its speed; 1 is full speed."
        }
        _ => return None,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_element_and_attribute_is_described_and_every_child_is_an_element() {
        for e in ELEMENTS {
            for a in e.attributes {
                assert!(attribute_doc(e.name, a).is_some(), "{}.{a}", e.name);
            }
            for r in e.required {
                assert!(e.attributes.contains(r), "{}.{r}", e.name);
            }
            for grandparent in [None, Some("BatteryRequirement")] {
                for child in children(Some(e.name), grandparent) {
                    assert!(element_info(child).is_some(), "{child}");
                }
            }
        }
    }
}
