//! Reading one `*.strategy.xml` file into the [`Strategy`] model, with
//! positioned diagnostics (E080–E084, W080, and E001–E003 for conditions that
//! do not parse). The file is first read into the positioned element tree of
//! [`crate::xmltree`], then the tree is read element by element.
//!
//! - Malformed XML (E080) stops the first step; what was read before is still
//!   read, and entries cut short are marked incomplete.
//! - A plain `<` inside an attribute value (the thesis's own files write
//!   `cond="distance<20"`) is E081 at the `<`, with `&lt;` as the fix; the
//!   value is read as meant and reading goes on.
//! - Entries are kept when an attribute is missing or malformed: the field is
//!   `None` and the rest is still checked.
//! - `<Condition cond="...">` is parsed with the mission expression grammar
//!   ([`crate::syntax::parse_expr_mapped`]), positioned inside the file even
//!   where the value is written with entities (`&lt;`).

use super::model::*;
use super::schema::*;
use crate::diag::{Code, Diagnostic, FileId, Sink};
use crate::syntax::ast::TimeUnit;
use crate::syntax::{parse_expr, parse_expr_mapped};
use crate::xmlpos::{Attr, get, is_ident, shown, suggest, value_offsets};
use crate::xmltree::{Elem, TreeFormat, Vocabulary, read_tree};

/// Reads one strategy file: the strategy (`None` when the file has no
/// `<Strategy>` root element) and the diagnostics of reading it. The checks of
/// [`super::check`] and [`super::machine`] are not run here.
pub fn read_strategy(file: FileId, text: &str) -> (Option<Strategy>, Vec<Diagnostic>) {
    let (root, diagnostics) = read_tree(
        text,
        TreeFormat {
            file,
            xml_code: Code::StrategyXml,
            empty_message: "this strategy file is empty: it needs a `<Strategy name=\"Team\">` element",
            raw_lt: Some(Code::StrategyRawLt),
        },
    );
    let mut sink = Sink::quoting_xml(file);
    sink.extend(diagnostics);
    let mut reader = Reader {
        file,
        text,
        diagnostics: sink,
    };
    let strategy = root.and_then(|root| reader.root(&root));
    (strategy, reader.diagnostics.into_vec())
}

/// Every element of the format, with where it belongs (for "not allowed here").
const ELEMENTS: &[(&str, &str)] = &[
    ("Strategy", "once, around the whole file"),
    ("ValueInfo", "inside `<Strategy>`"),
    ("ServiceInfo", "inside `<Strategy>`"),
    ("GroupingInfo", "inside `<Strategy>`"),
    ("NonFunctionalInfo", "inside `<Strategy>`"),
    ("Value", "inside `<ValueInfo>`"),
    ("Service", "inside `<ServiceInfo>`"),
    ("TargetRobot", "inside `<Value>` or `<Service>`"),
    ("CheckSensor", "inside `<Value>` or `<Action>`"),
    ("ExecuteAlgorithm", "inside `<Value>` or `<Action>`"),
    ("ExecuteActuator", "inside `<Action>`"),
    (
        "Parameter",
        "inside `<Action>`, `<CheckSensor>`, `<ExecuteActuator>` or `<ExecuteAlgorithm>`",
    ),
    ("ActionInfo", "inside `<Service>`"),
    ("Action", "inside `<ActionInfo>`"),
    ("TransitionInfo", "inside `<Action>`"),
    ("Transition", "inside `<TransitionInfo>`"),
    (
        "Condition",
        "inside `<Transition>` or `<BatteryRequirement>`",
    ),
    ("LeaderSelectionInfo", "inside `<GroupingInfo>`"),
    ("GroupSync", "inside `<GroupingInfo>`"),
    ("GroupService", "inside `<GroupingInfo>`"),
    ("SharedOwner", "inside `<GroupingInfo>`"),
    ("BatteryRequirement", "inside `<NonFunctionalInfo>`"),
    (
        "Sensor",
        "inside the `<Condition>` of a `<BatteryRequirement>`",
    ),
    (
        "Actuator",
        "inside the `<Condition>` of a `<BatteryRequirement>`",
    ),
];

struct Reader<'t> {
    file: FileId,
    text: &'t str,
    diagnostics: Sink,
}

impl Reader<'_> {
    // --- shared helpers ----------------------------------------------------

    fn vocabulary(&self) -> Vocabulary<'static> {
        Vocabulary {
            file: self.file,
            unknown_attribute: Code::StrategyUnknownAttribute,
            unknown_element: Code::StrategyUnknownElement,
            elements: ELEMENTS,
        }
    }

    /// W080 for attributes that the element does not have.
    fn check_attributes(&mut self, e: &Elem, allowed: &[&str]) {
        self.vocabulary()
            .check_attributes(&mut self.diagnostics, e, allowed, |_| None);
    }

    /// The children among `allowed`; E082 for the others and for text.
    fn children<'e>(&mut self, e: &'e Elem, allowed: &[&str]) -> Vec<&'e Elem> {
        self.vocabulary()
            .children(&mut self.diagnostics, e, allowed)
    }

    /// An element with no attributes of its own around a list of `child`
    /// elements (`<ActionInfo>` around `<Action>`s): each child read by `read`.
    fn entries<'e, T>(
        &mut self,
        wrapper: &'e Elem,
        child: &str,
        mut read: impl FnMut(&mut Self, &'e Elem) -> T,
    ) -> Vec<T> {
        self.check_attributes(wrapper, &[]);
        let children = self.children(wrapper, &[child]);
        children.into_iter().map(|c| read(self, c)).collect()
    }

    /// An element with attributes among `allowed` and no children.
    fn leaf(&mut self, e: &Elem, allowed: &[&str]) {
        self.check_attributes(e, allowed);
        self.children(e, &[]);
    }

    /// At most one child named `name` among `children`: E085 for the others.
    fn at_most_one<'e>(&mut self, children: &[&'e Elem], name: &str) -> Option<&'e Elem> {
        let mut found = children.iter().filter(|c| c.local == name);
        let first = found.next().copied()?;
        for again in found {
            self.diagnostics
                .report(
                    Code::StrategyDuplicate,
                    again.name_span,
                    format!("`<{name}>` is given twice here: write it once"),
                )
                .relate(first.name_span, "first given here");
        }
        Some(first)
    }

    /// E083 unless `e` (complete) has a child named `child`.
    fn require_child(&mut self, e: &Elem, children: &[&Elem], child: &str, what: &str) {
        if e.complete && !children.iter().any(|c| c.local == child) {
            let message = format!("`<{}>` needs {what}", e.local);
            self.diagnostics
                .report(Code::StrategyMissingAttribute, e.tag, message);
        }
    }

    /// A required attribute: E083 when missing, E084 when blank.
    fn required<'e>(&mut self, e: &'e Elem, key: &str) -> Option<&'e Attr> {
        // The schema's list is what completion inserts and the docs show.
        debug_assert!(
            element_info(&e.local).is_some_and(|info| info.required.contains(&key)),
            "strategy::schema does not list `{key}` as required on `<{}>`",
            e.local
        );
        match get(&e.attrs, key) {
            None => {
                let message = format!("`<{}>` needs a `{key}` attribute", e.local);
                self.diagnostics
                    .report(Code::StrategyMissingAttribute, e.tag, message);
                None
            }
            Some(a) => self.not_blank(a),
        }
    }

    /// An optional attribute: E084 when blank.
    fn optional<'e>(&mut self, e: &'e Elem, key: &str) -> Option<&'e Attr> {
        get(&e.attrs, key).and_then(|a| self.not_blank(a))
    }

    fn not_blank<'a>(&mut self, a: &'a Attr) -> Option<&'a Attr> {
        if a.trimmed().is_empty() {
            let message = format!("`{}` is empty", a.key);
            self.diagnostics
                .report(Code::StrategyBadAttribute, a.span, message);
            return None;
        }
        Some(a)
    }

    fn named(a: &Attr) -> Named {
        Named {
            name: a.trimmed().to_string(),
            span: a.trimmed_span(),
        }
    }

    /// A name that conditions or missions refer to: E084 (and `None`) unless
    /// it is an identifier.
    fn ident(&mut self, a: Option<&Attr>) -> Option<Named> {
        let named = Self::named(a?);
        if is_ident(&named.name) {
            return Some(named);
        }
        let message = format!(
            "`{}` must be a name of letters, digits and `_`, not starting with a digit, not `{}`",
            a?.key,
            shown(&named.name)
        );
        self.diagnostics
            .report(Code::StrategyBadAttribute, named.span, message);
        None
    }

    /// A whole number (at least `min`); E084 otherwise.
    fn number(&mut self, a: &Attr, min: u64) -> Option<u64> {
        let s = a.trimmed();
        let digits = !s.is_empty() && s.bytes().all(|b| b.is_ascii_digit());
        match s.parse::<u64>() {
            Ok(n) if digits && n >= min => Some(n),
            _ => {
                let what = if min == 0 {
                    "a whole number (0 or more)"
                } else {
                    "a positive whole number"
                };
                let message = if digits && s.parse::<u64>().is_err() {
                    format!("`{}` is too large: `{}`", a.key, shown(s))
                } else {
                    format!("`{}` must be {what}, not `{}`", a.key, shown(s))
                };
                self.diagnostics
                    .report(Code::StrategyBadAttribute, a.trimmed_span(), message);
                None
            }
        }
    }

    fn id(&mut self, a: Option<&Attr>) -> Option<ActionId> {
        let a = a?;
        let value = self.number(a, 0)?;
        Some(ActionId {
            value,
            span: a.trimmed_span(),
        })
    }

    /// One of a few words; E084 with a did-you-mean otherwise.
    fn choice<T: Copy>(&mut self, a: &Attr, options: &[(&str, T)]) -> Option<T> {
        let s = a.trimmed();
        if let Some((_, v)) = options.iter().find(|(o, _)| *o == s) {
            return Some(*v);
        }
        let words: Vec<&str> = options.iter().map(|(o, _)| *o).collect();
        let list = match words.as_slice() {
            [init @ .., last] if !init.is_empty() => format!(
                "{} or `{last}`",
                init.iter()
                    .map(|o| format!("`{o}`"))
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
            _ => words.iter().map(|o| format!("`{o}`")).collect(),
        };
        let message = format!("`{}` must be {list}, not `{}`", a.key, shown(s));
        let guess = words
            .iter()
            .find(|w| w.eq_ignore_ascii_case(s))
            .map(|w| w.to_string())
            .or_else(|| suggest(s, &words));
        self.diagnostics
            .report(Code::StrategyBadAttribute, a.span, message)
            .suggest(guess);
        None
    }

    /// `Yes` or `No` (absent is `No`); E084 otherwise.
    fn yes_no(&mut self, e: &Elem, key: &str) -> YesNo {
        let Some(a) = get(&e.attrs, key) else {
            return YesNo::No;
        };
        match self.choice(a, &[("Yes", true), ("No", false)]) {
            Some(true) => YesNo::Yes(a.trimmed_span()),
            Some(false) => YesNo::No,
            None => YesNo::Malformed(a.span),
        }
    }

    /// A period such as `1 SEC` (units as in missions); E084 otherwise.
    fn duration(&mut self, a: Option<&Attr>) -> Option<Duration> {
        let a = a?;
        let mut words = a.trimmed().split_whitespace();
        let parsed = match (words.next(), words.next(), words.next()) {
            (Some(amount), Some(unit), None) => amount
                .parse::<f64>()
                .ok()
                .zip(TimeUnit::parse(unit))
                .map(|(n, u)| n * u.millis())
                .filter(|ms| ms.is_finite() && *ms > 0.0),
            _ => None,
        };
        match parsed {
            Some(millis) => Some(Duration {
                millis,
                span: a.trimmed_span(),
            }),
            None => {
                let message = format!(
                    "`{}` must be a positive period such as `1 SEC` (MSEC, SEC, MIN or HOUR), not `{}`",
                    a.key,
                    shown(a.trimmed())
                );
                self.diagnostics
                    .report(Code::StrategyBadAttribute, a.span, message);
                None
            }
        }
    }

    /// `cond="..."`, parsed with the mission expression grammar.
    fn condition(&mut self, e: &Elem) -> Option<Condition> {
        let a = self.required(e, "cond")?;
        let parse = if a.exact {
            parse_expr(self.file, &a.value, a.span.start)
        } else {
            let offsets = value_offsets(self.text, a);
            let last = offsets.len().saturating_sub(1);
            parse_expr_mapped(self.file, &a.value, |i| offsets[i.min(last)])
        };
        self.diagnostics.extend(parse.diagnostics);
        Some(Condition {
            text: a.value.to_string(),
            span: a.span,
            expr: parse.expr,
        })
    }

    // --- the format ----------------------------------------------------------

    fn root(&mut self, root: &Elem) -> Option<Strategy> {
        if root.local != "Strategy" {
            let message = format!(
                "a strategy file must start with `<Strategy name=\"Team\">`, not `<{}>`",
                root.qname
            );
            self.diagnostics
                .report(Code::StrategyUnknownElement, root.name_span, message)
                .suggest(suggest(&root.local, &["Strategy"]));
            return None;
        }
        self.check_attributes(root, STRATEGY_ATTRS);
        let team = self.required(root, "name");
        let team = self.ident(team);
        let children = self.children(
            root,
            &[
                "ValueInfo",
                "ServiceInfo",
                "GroupingInfo",
                "NonFunctionalInfo",
            ],
        );
        let mut strategy = Strategy {
            file: self.file,
            team,
            tag: root.tag,
            values: Vec::new(),
            services: Vec::new(),
            grouping: None,
            battery_rules: Vec::new(),
        };
        for name in [
            "ValueInfo",
            "ServiceInfo",
            "GroupingInfo",
            "NonFunctionalInfo",
        ] {
            self.at_most_one(&children, name);
        }
        for section in children {
            match section.local.as_str() {
                "ValueInfo" => {
                    let values = self.entries(section, "Value", Self::value);
                    strategy.values.extend(values);
                }
                "ServiceInfo" => {
                    let services = self.entries(section, "Service", Self::service);
                    strategy.services.extend(services);
                }
                "GroupingInfo" => {
                    let grouping = self.grouping(section);
                    strategy.grouping = strategy.grouping.take().or(Some(grouping));
                }
                _ => {
                    let rules = self.entries(section, "BatteryRequirement", |r, b| {
                        r.entries(b, "Condition", Self::battery_rule)
                    });
                    strategy.battery_rules.extend(rules.into_iter().flatten());
                }
            }
        }
        Some(strategy)
    }

    fn target(&mut self, e: &Elem) -> TargetRobot {
        self.leaf(e, TARGET_ATTRS);
        let name = self.required(e, "name");
        let name = self.ident(name);
        let nick_name = self.optional(e, "nickName");
        let nick_name = self.ident(nick_name);
        let ea = self.optional(e, "ea").map(Self::named);
        TargetRobot {
            name,
            nick_name,
            ea,
            span: e.span,
        }
    }

    fn value(&mut self, e: &Elem) -> ValueEntry {
        self.check_attributes(e, VALUE_ATTRS);
        let name = self.required(e, "name");
        let name = self.ident(name);
        let children = self.children(e, &["TargetRobot", "CheckSensor", "ExecuteAlgorithm"]);
        self.require_child(
            e,
            &children,
            "TargetRobot",
            "a `<TargetRobot name=\"...\"/>`",
        );
        let mut entry = ValueEntry {
            name,
            targets: Vec::new(),
            tasks: Vec::new(),
            span: e.span,
            tag: e.tag,
        };
        for c in children {
            if c.local == "TargetRobot" {
                entry.targets.push(self.target(c));
            } else {
                entry.tasks.push(self.task_use(c));
            }
        }
        entry
    }

    fn task_use(&mut self, e: &Elem) -> TaskUse {
        let kind = TaskUseKind::ALL
            .iter()
            .find(|(tag, _)| *tag == e.local)
            .map_or(TaskUseKind::CheckSensor, |(_, k)| *k);
        self.check_attributes(e, TASK_USE_ATTRS);
        let name = self.required(e, "name").map(Self::named);
        let parameters = self
            .children(e, &["Parameter"])
            .into_iter()
            .map(|p| self.parameter(p))
            .collect();
        TaskUse {
            kind,
            name,
            parameters,
            span: e.span,
        }
    }

    fn parameter(&mut self, e: &Elem) -> Parameter {
        self.leaf(e, PARAMETER_ATTRS);
        let name = self.required(e, "name");
        let name = self.ident(name);
        let ty = self.required(e, "type").map(Self::named);
        let data = self
            .required(e, "dataCharacteristic")
            .and_then(|a| self.choice(a, &DataCharacteristic::ALL));
        let size = self.optional(e, "size").and_then(|a| self.number(a, 1));
        let value = get(&e.attrs, "value").map(Self::named);
        let src_task = self.optional(e, "srcTask").map(Self::named);
        let dst_task = self.optional(e, "dstTask").map(Self::named);
        // Where the data goes: a channel joins two tasks, a request is sent to one.
        let needs: &[&str] = match data {
            Some(DataCharacteristic::Channel) => &["srcTask", "dstTask"],
            Some(DataCharacteristic::SysRequest) => &["dstTask"],
            _ => &[],
        };
        for key in needs {
            if get(&e.attrs, key).is_none() {
                let message = format!(
                    "a `{}` parameter needs a `{key}` attribute: the task it {}",
                    data.map_or("", DataCharacteristic::as_str),
                    if *key == "srcTask" {
                        "comes from"
                    } else {
                        "goes to"
                    }
                );
                self.diagnostics
                    .report(Code::StrategyMissingAttribute, e.tag, message);
            }
        }
        Parameter {
            name,
            ty,
            data,
            size,
            value,
            src_task,
            dst_task,
            span: e.span,
        }
    }

    fn service(&mut self, e: &Elem) -> ServiceEntry {
        self.check_attributes(e, SERVICE_ATTRS);
        let plan = self.required(e, "plan_name");
        let plan = self.ident(plan);
        // `service_name` is an alias of `name`.
        let name = match (get(&e.attrs, "name"), get(&e.attrs, "service_name")) {
            (Some(a), Some(b)) => {
                if a.trimmed() != b.trimmed() {
                    self.diagnostics
                        .report(
                            Code::StrategyBadAttribute,
                            b.span,
                            "`service_name` is another spelling of `name`: give one of them",
                        )
                        .relate(a.span, "`name` is given here");
                }
                self.not_blank(a)
            }
            (Some(a), None) | (None, Some(a)) => self.not_blank(a),
            (None, None) => {
                self.diagnostics.report(
                    Code::StrategyMissingAttribute,
                    e.tag,
                    "`<Service>` needs a `name` attribute: the service it refines, such as `move`",
                );
                None
            }
        };
        let name = self.ident(name);
        let children = self.children(e, &["TargetRobot", "ActionInfo"]);
        self.require_child(
            e,
            &children,
            "TargetRobot",
            "a `<TargetRobot name=\"...\"/>`",
        );
        self.require_child(
            e,
            &children,
            "ActionInfo",
            "an `<ActionInfo>` with its actions",
        );
        let info = self.at_most_one(&children, "ActionInfo");
        let mut entry = ServiceEntry {
            plan,
            name,
            targets: Vec::new(),
            actions: Vec::new(),
            span: e.span,
            tag: e.tag,
            complete: e.complete && info.is_none_or(|i| i.complete),
        };
        for c in children {
            if c.local == "TargetRobot" {
                entry.targets.push(self.target(c));
            }
        }
        if let Some(info) = info {
            entry.actions = self.entries(info, "Action", Self::action);
        }
        entry
    }

    fn action(&mut self, e: &Elem) -> Action {
        self.check_attributes(e, ACTION_ATTRS);
        let name = self.required(e, "name");
        let name = self.ident(name);
        let id = self.required(e, "actionId");
        let id = self.id(id);
        let initial = self.yes_no(e, "initial");
        let is_final = self.yes_no(e, "final");
        let children = self.children(
            e,
            &[
                "CheckSensor",
                "ExecuteActuator",
                "ExecuteAlgorithm",
                "Parameter",
                "TransitionInfo",
            ],
        );
        let mut action = Action {
            name,
            id,
            initial,
            is_final,
            tasks: Vec::new(),
            parameters: Vec::new(),
            transitions: Vec::new(),
            span: e.span,
            tag: e.tag,
        };
        let info = self.at_most_one(&children, "TransitionInfo");
        for c in children {
            match c.local.as_str() {
                "Parameter" => action.parameters.push(self.parameter(c)),
                "TransitionInfo" => {}
                _ => action.tasks.push(self.task_use(c)),
            }
        }
        if let Some(info) = info {
            action.transitions = self.entries(info, "Transition", Self::transition);
        }
        action
    }

    fn transition(&mut self, e: &Elem) -> Transition {
        self.check_attributes(e, TRANSITION_ATTRS);
        let src = self.required(e, "srcId");
        let src = self.id(src);
        let dst = self.required(e, "dstId");
        let dst = self.id(dst);
        let children = self.children(e, &["Condition"]);
        let condition = self.at_most_one(&children, "Condition").and_then(|c| {
            self.leaf(c, CONDITION_ATTRS);
            self.condition(c)
        });
        Transition {
            src,
            dst,
            condition,
            span: e.span,
        }
    }

    fn grouping(&mut self, e: &Elem) -> Grouping {
        self.check_attributes(e, &[]);
        let children = self.children(
            e,
            &[
                "LeaderSelectionInfo",
                "GroupSync",
                "GroupService",
                "SharedOwner",
            ],
        );
        let leader = self.at_most_one(&children, "LeaderSelectionInfo");
        let sync = self.at_most_one(&children, "GroupSync");
        let owner = self.at_most_one(&children, "SharedOwner");
        let shared_owner = owner.map(|o| {
            self.leaf(o, SHARED_OWNER_ATTRS);
            let library = self.required(o, "library");
            let library = self.ident(library);
            let robot = self.required(o, "robot");
            let robot = self.ident(robot);
            SharedOwner {
                library,
                robot,
                span: o.span,
            }
        });
        let leader_selection = leader.map(|l| {
            self.leaf(l, LEADER_ATTRS);
            let algorithm = self
                .required(l, "algorithm")
                .and_then(|a| self.choice(a, &LeaderAlgorithm::ALL));
            let heartbeat = self.optional(l, "heartbeatPeriod");
            let heartbeat = self.duration(heartbeat);
            let plan = self.optional(l, "plan_name");
            let plan = self.ident(plan);
            let service = self.optional(l, "cs_name");
            let service = self.ident(service);
            for (has, lacks) in [("plan_name", "cs_name"), ("cs_name", "plan_name")] {
                if let (Some(a), None) = (get(&l.attrs, has), get(&l.attrs, lacks)) {
                    let message = format!(
                        "`{has}` needs `{lacks}` too: together they name the composite service whose leader is elected"
                    );
                    self.diagnostics.report(Code::StrategyMissingAttribute, a.key_span, message);
                }
            }
            LeaderSelection {
                algorithm,
                heartbeat,
                plan,
                service,
                span: l.span,
            }
        });
        let sync_timeout = sync.and_then(|s| {
            self.leaf(s, SYNC_ATTRS);
            let timeout = self.required(s, "timeout");
            self.duration(timeout)
        });
        let group_services = children
            .iter()
            .filter(|c| c.local == "GroupService")
            .map(|g| {
                self.leaf(g, GROUP_SERVICE_ATTRS);
                let name = self.required(g, "name");
                let name = self.ident(name);
                let plan = self.optional(g, "plan_name");
                let plan = self.ident(plan);
                GroupService {
                    name,
                    plan,
                    span: g.span,
                }
            })
            .collect();
        Grouping {
            leader_selection,
            sync_timeout,
            group_services,
            shared_owner,
            span: e.span,
        }
    }

    fn battery_rule(&mut self, e: &Elem) -> BatteryRule {
        self.check_attributes(e, CONDITION_ATTRS);
        let condition = self.condition(e);
        let mut rule = BatteryRule {
            condition,
            sensors: Vec::new(),
            actuators: Vec::new(),
            span: e.span,
        };
        for c in self.children(e, &["Sensor", "Actuator"]) {
            let (attrs, level_key) = if c.local == "Sensor" {
                (SENSOR_ATTRS, "periodLevel")
            } else {
                (ACTUATOR_ATTRS, "speedLevel")
            };
            self.leaf(c, attrs);
            let name = self.required(c, "name").map(Self::named);
            // Levels count from 1, the task's own period or full speed.
            let level = self.required(c, level_key).and_then(|a| self.number(a, 1));
            let setting = LevelSetting {
                name,
                level,
                span: c.span,
            };
            if c.local == "Sensor" {
                rule.sensors.push(setting);
            } else {
                rule.actuators.push(setting);
            }
        }
        rule
    }
}
