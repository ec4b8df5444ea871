//! The robot catalog: what each robot type is (platform, capabilities), knows
//! (values) and can do (built-in services). Built from the embedded built-in
//! catalog plus `*.robot.xml` files, which add types or override built-in ones by
//! type name. The format's reference is `docs/catalog.md`.

mod builtin;
pub mod latency;
pub mod schema;
mod xml;

pub use builtin::{BUILTIN_FILE, BUILTIN_NAME, BUILTIN_SOURCE, builtin_catalog};
pub use xml::{ParsedCatalog, ParsedRobot, parse_catalog, parse_catalog_file};

use crate::diag::{Code, Diagnostic, FileId, Related};
use crate::span::Span;
use std::collections::HashMap;
use std::fmt;
use std::path::Path;

/// One user catalog file (`*.robot.xml`) to load.
#[derive(Clone, Copy, Debug)]
pub struct CatalogSource<'a> {
    pub file: FileId,
    pub text: &'a str,
    /// The folder of the file, for `graph=` paths; `None` skips that check.
    pub base_dir: Option<&'a Path>,
}

/// The catalog of a check: the built-in catalog, then each user file in order.
/// A user type replaces a built-in type of the same name (or alias); a type
/// defined in two user files is an error (E053) and the first one is kept. A
/// user file's `<Operator>` replaces the built-in `USER` pseudo-robot.
pub fn load_catalog(sources: &[CatalogSource<'_>]) -> (Catalog, Vec<Diagnostic>) {
    let mut catalog = builtin_catalog();
    let mut diags = Vec::new();
    // Names defined by user files so far, to where they are written.
    let mut defined: HashMap<String, (FileId, Span)> = HashMap::new();
    for source in sources {
        let parsed = parse_catalog(source.file, source.text, source.base_dir);
        diags.extend(parsed.diagnostics);
        let robots = parsed.robots.into_iter().map(|r| (r, false));
        for (ParsedRobot { mut robot, names }, operator) in
            robots.chain(parsed.operator.map(|r| (r, true)))
        {
            let mut kept = Vec::new();
            for (i, (name, span)) in names.into_iter().enumerate() {
                if let Some(&(first_file, first_span)) = defined.get(&name) {
                    let what = if i == 0 { "robot type" } else { "alias" };
                    let mut d = Diagnostic::new(
                        Code::CatalogDuplicateType,
                        source.file,
                        span,
                        format!("{what} `{name}` is already defined in another catalog file"),
                    );
                    d.related.push(Related {
                        file: first_file,
                        span: first_span,
                        message: "first defined here".to_string(),
                    });
                    diags.push(d);
                    if i == 0 {
                        break;
                    }
                    robot.aliases.retain(|a| *a != name);
                    continue;
                }
                kept.push((name, span));
            }
            if kept.first().map(|(n, _)| n) != Some(&robot.name) {
                continue; // the type itself was a duplicate
            }
            for (name, span) in kept {
                defined.insert(name, (source.file, span));
            }
            if operator {
                catalog.set_user(robot);
            } else {
                catalog.insert(robot);
            }
        }
    }
    (catalog, diags)
}

/// Where a catalog entry was written: the file and the byte range of its element.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Origin {
    pub file: FileId,
    pub span: Span,
}

/// The type of a robot value or of a service parameter.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum ValueType {
    Int,
    Float,
    Bool,
    String,
    Location,
    Image,
    /// An enumeration with its allowed symbolic constants.
    Enum(Vec<String>),
}

impl ValueType {
    /// Parses the `type=` attribute; `domain` is the `domain=` attribute (for `enum`).
    pub fn parse(name: &str, domain: Option<&str>) -> Option<ValueType> {
        Some(match name {
            "int" => ValueType::Int,
            "float" => ValueType::Float,
            "bool" => ValueType::Bool,
            "string" => ValueType::String,
            "location" => ValueType::Location,
            "image" => ValueType::Image,
            "enum" => ValueType::Enum(
                domain
                    .unwrap_or("")
                    .split_whitespace()
                    .map(str::to_string)
                    .collect(),
            ),
            _ => return None,
        })
    }

    pub fn name(&self) -> &'static str {
        match self {
            ValueType::Int => "int",
            ValueType::Float => "float",
            ValueType::Bool => "bool",
            ValueType::String => "string",
            ValueType::Location => "location",
            ValueType::Image => "image",
            ValueType::Enum(_) => "enum",
        }
    }
}

impl fmt::Display for ValueType {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ValueType::Enum(domain) => write!(f, "enum {{{}}}", domain.join(", ")),
            other => f.write_str(other.name()),
        }
    }
}

/// How a value or service is implemented: one library task, or a task-graph file.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Implementation {
    Task(String),
    Graph(String),
    /// Neither was given (allowed for the built-in catalog's generic services).
    Unspecified,
}

#[derive(Clone, Debug, PartialEq, Eq, Default)]
pub struct Platform {
    /// The platform its programs are built for (`target="cortex-m"`), and
    /// where that is written; `None`: not said (`semo build` then builds
    /// for `linux`, unless told otherwise).
    pub target: Option<(crate::platform::Target, Span)>,
    pub os: String,
    pub cpu: String,
    pub cores: Option<u32>,
    pub clock_mhz: Option<u32>,
    pub memory_kb: Option<u64>,
    /// Free text for platforms with several processors (e.g. "+ OpenCR Cortex-M7").
    pub note: String,
}

#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ValueDef {
    pub name: String,
    /// Other accepted spellings (`USER.cmd` for `USER.RC_CMD`).
    pub aliases: Vec<String>,
    pub ty: ValueType,
    pub unit: Option<String>,
    pub doc: String,
    pub implementation: Implementation,
    pub origin: Origin,
}

#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ParamDef {
    pub name: String,
    pub ty: ValueType,
    pub optional: bool,
}

/// One result of a `<Service>`: a value the service's task gives back when
/// a call is done, which a mission binds to a name
/// (`FOUND, WHERE = search(red)`, `docs/language/services.md`).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ResultDef {
    pub name: String,
    pub ty: ValueType,
    pub doc: String,
}

#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ServiceDef {
    pub name: String,
    /// Other accepted spellings (`stand_by` for `standby`).
    pub aliases: Vec<String>,
    pub params: Vec<ParamDef>,
    /// What a call gives back when it is done, in order (`<Result>`).
    pub results: Vec<ResultDef>,
    pub doc: String,
    pub implementation: Implementation,
    /// The latency bounds stated on its task graph (`<Latency>`; only a
    /// `graph=` service has them).
    pub latency: Vec<latency::LatencyBound>,
    pub origin: Origin,
}

impl ServiceDef {
    pub fn required_params(&self) -> usize {
        self.params.iter().filter(|p| !p.optional).count()
    }

    /// `move(goal?: location)`, for hovers and messages.
    pub fn signature(&self) -> String {
        let params: Vec<String> = self
            .params
            .iter()
            .map(|p| format!("{}{}: {}", p.name, if p.optional { "?" } else { "" }, p.ty))
            .collect();
        format!("{}({})", self.name, params.join(", "))
    }

    /// `FOUND: bool, WHERE: location`, for hovers and messages; empty
    /// when the service gives nothing back.
    pub fn results_signature(&self) -> String {
        let results: Vec<String> = self
            .results
            .iter()
            .map(|r| format!("{}: {}", r.name, r.ty))
            .collect();
        results.join(", ")
    }
}

#[derive(Clone, Debug, PartialEq, Eq)]
pub struct RobotType {
    pub name: String,
    pub aliases: Vec<String>,
    pub doc: String,
    pub platform: Platform,
    pub capabilities: Vec<String>,
    pub values: Vec<ValueDef>,
    pub services: Vec<ServiceDef>,
    pub origin: Origin,
}

impl RobotType {
    pub fn value(&self, name: &str) -> Option<&ValueDef> {
        self.values
            .iter()
            .find(|v| v.name == name || v.aliases.iter().any(|a| a == name))
    }

    pub fn service(&self, name: &str) -> Option<&ServiceDef> {
        self.services
            .iter()
            .find(|s| s.name == name || s.aliases.iter().any(|a| a == name))
    }

    pub fn has_capability(&self, name: &str) -> bool {
        self.capabilities.iter().any(|c| c == name)
    }
}

/// Identifies a robot type inside one [`Catalog`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct RobotTypeId(pub u32);

/// All robot types known to a check: the built-in ones, then user files.
#[derive(Clone, Debug, Default)]
pub struct Catalog {
    robots: Vec<RobotType>,
    /// Type names and aliases to their robot.
    by_name: HashMap<String, RobotTypeId>,
    /// The `USER` pseudo-robot (the operator console).
    user: Option<RobotType>,
}

impl Catalog {
    /// Builds a catalog from types in order; a later type with the same name (or an
    /// alias of an earlier one) replaces the earlier one. Duplicate detection within
    /// one user file is the loader's job.
    pub fn from_types(types: impl IntoIterator<Item = RobotType>) -> Catalog {
        let mut catalog = Catalog::default();
        for robot in types {
            catalog.insert(robot);
        }
        catalog
    }

    /// Adds `robot`, replacing any type it shares its name or an alias with.
    pub fn insert(&mut self, robot: RobotType) {
        let existing = std::iter::once(&robot.name)
            .chain(&robot.aliases)
            .find_map(|n| self.by_name.get(n).copied());
        let id = match existing {
            Some(id) => {
                let old = &self.robots[id.0 as usize];
                for n in std::iter::once(&old.name).chain(&old.aliases) {
                    self.by_name.remove(n);
                }
                self.robots[id.0 as usize] = robot;
                id
            }
            None => {
                self.robots.push(robot);
                RobotTypeId(self.robots.len() as u32 - 1)
            }
        };
        let robot = &self.robots[id.0 as usize];
        for n in std::iter::once(&robot.name).chain(&robot.aliases) {
            self.by_name.insert(n.clone(), id);
        }
    }

    pub fn set_user(&mut self, user: RobotType) {
        self.user = Some(user);
    }

    /// The operator console's pseudo-robot (`USER`), with its values (`RC_CMD`).
    pub fn user(&self) -> Option<&RobotType> {
        self.user.as_ref()
    }

    pub fn lookup(&self, name: &str) -> Option<RobotTypeId> {
        self.by_name.get(name).copied()
    }

    pub fn get(&self, id: RobotTypeId) -> &RobotType {
        &self.robots[id.0 as usize]
    }

    pub fn robot(&self, name: &str) -> Option<&RobotType> {
        self.lookup(name).map(|id| self.get(id))
    }

    pub fn types(&self) -> impl Iterator<Item = (RobotTypeId, &RobotType)> {
        self.robots
            .iter()
            .enumerate()
            .map(|(i, r)| (RobotTypeId(i as u32), r))
    }

    /// Every type name and alias, for did-you-mean.
    pub fn names(&self) -> impl Iterator<Item = &str> {
        self.by_name.keys().map(String::as_str)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn source(file: u32, text: &str) -> CatalogSource<'_> {
        CatalogSource {
            file: FileId(file),
            text,
            base_dir: None,
        }
    }

    #[test]
    fn load_without_sources_is_the_builtin_catalog() {
        let (catalog, diags) = load_catalog(&[]);
        assert!(diags.is_empty());
        assert_eq!(catalog.types().count(), 6);
        assert!(catalog.user().is_some());
    }

    #[test]
    fn user_types_add_and_override() {
        let a = r#"<Catalog>
  <Robot type="MyBot"><Value name="HEAT" type="int" doc="Heat."/></Robot>
  <Robot type="NXTLego" aliases="lego_robot"><Doc>My own NXT.</Doc></Robot>
</Catalog>"#;
        let (catalog, diags) = load_catalog(&[source(1, a)]);
        assert!(diags.is_empty(), "{diags:#?}");
        assert_eq!(catalog.types().count(), 7);
        let my = catalog.robot("MyBot").unwrap();
        assert_eq!(my.origin.file, FileId(1));
        assert!(my.value("HEAT").is_some());
        let nxt = catalog.robot("lego_robot").unwrap();
        assert_eq!(nxt.doc, "My own NXT.");
        assert!(nxt.service("search").is_none());
        // The other built-in types stay.
        assert!(catalog.robot("iRobotCreate").is_some());
    }

    #[test]
    fn type_defined_in_two_user_files() {
        let a = "<Catalog>\n<Robot type=\"MyBot\" aliases=\"mb\"/>\n</Catalog>";
        let b = "<Catalog>\n<Robot type=\"MyBot\"><Doc>second</Doc></Robot>\n<Robot type=\"Other\" aliases=\"mb o\"/>\n</Catalog>";
        let (catalog, diags) = load_catalog(&[source(1, a), source(2, b)]);
        assert_eq!(diags.len(), 2, "{diags:#?}");
        assert!(diags.iter().all(|d| d.code == Code::CatalogDuplicateType));
        assert_eq!(diags[0].file, FileId(2));
        assert_eq!(&b[diags[0].span.range()], "MyBot");
        assert_eq!(diags[0].related[0].file, FileId(1));
        assert_eq!(&a[diags[0].related[0].span.range()], "MyBot");
        assert_eq!(&b[diags[1].span.range()], "mb");
        assert_eq!(&a[diags[1].related[0].span.range()], "mb");
        // The first definition is kept; the alias clash only drops the alias.
        assert_eq!(catalog.robot("MyBot").unwrap().doc, "");
        assert_eq!(catalog.robot("mb").unwrap().name, "MyBot");
        assert_eq!(catalog.robot("o").unwrap().name, "Other");
    }

    #[test]
    fn user_file_operator_replaces_user() {
        let a = r#"<Catalog><Operator type="USER" aliases="user">
  <Value name="RC_CMD" type="string" aliases="cmd"/>
  <Value name="GOAL" type="location"/>
</Operator></Catalog>"#;
        let (catalog, diags) = load_catalog(&[source(1, a)]);
        assert!(diags.is_empty(), "{diags:#?}");
        assert!(catalog.user().unwrap().value("GOAL").is_some());
        assert!(catalog.robot("USER").is_none());
    }

    /// Each catalog fixture of the end-to-end harness yields its code, and only it.
    #[test]
    fn catalog_fixtures_produce_their_code() {
        let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../tests/fixtures/diagnostics");
        let mut seen = 0;
        for entry in std::fs::read_dir(&root).expect("fixture folder") {
            let dir = entry.unwrap().path();
            let name = dir.file_name().unwrap().to_string_lossy().into_owned();
            let Some(code) = Code::from_code(&name[..name.len().min(4)]) else {
                continue;
            };
            if !matches!(&name[..3], "E05" | "W05") {
                continue;
            }
            for file in std::fs::read_dir(&dir).unwrap() {
                let path = file.unwrap().path();
                if !path.to_string_lossy().ends_with(".robot.xml") {
                    continue;
                }
                let text = std::fs::read_to_string(&path).unwrap();
                let (catalog, diags) = load_catalog(&[CatalogSource {
                    file: FileId(1),
                    text: &text,
                    base_dir: Some(&dir),
                }]);
                assert!(!diags.is_empty(), "{name}: no diagnostic");
                assert!(diags.iter().all(|d| d.code == code), "{name}: {diags:#?}");
                assert!(
                    catalog.robot("MyBot").unwrap().service("move").is_some(),
                    "{name}"
                );
                seen += 1;
            }
        }
        assert_eq!(seen, 9);
    }
}
