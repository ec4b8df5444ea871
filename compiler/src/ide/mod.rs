//! Editor features, as plain data in byte spans (as rust-analyzer's `ide`
//! crate): no protocol type, no position other than byte offsets. One
//! submodule per kind of file, all speaking the vocabulary defined here:
//!
//! - [`mission`]: missions (completion, hover, navigation, rename, ...);
//! - [`strategy`]: strategy files;
//! - [`taskgraph`]: task graphs (ours and SDF3).
//!
//! The facade is [`crate::host::Analysis`]: its position queries
//! (`hover`, `completions`, `definition`, ... over a [`FilePosition`]) find
//! the file's kind, gather what that kind's features read (the checked
//! mission, the catalog the file sees, the missions a strategy file is
//! checked against) and dispatch here. A door (the language server, a test)
//! asks the facade, never a submodule, and turns the vocabulary into its own
//! types in one place (the server's `to_proto`). A new kind of file adds a
//! submodule here and one arm per query in `host/ide.rs`.

pub mod mission;
pub mod strategy;
pub mod taskgraph;

use crate::diag::FileId;
use crate::span::Span;

pub use crate::edit::{CodeAction, TextEdit};
pub use mission::folding::{Fold, FoldKind};
pub use mission::navigation::{Access, Reference};
pub use mission::rename::RenameError;
pub use mission::semantic_tokens::{HighlightToken, MODIFIERS as TOKEN_MODIFIERS, TokenKind};
pub use mission::signature_help::SignatureHelp;

/// A byte offset in one file of the workspace: what every position query asks
/// about.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct FilePosition {
    pub file: FileId,
    pub offset: usize,
}

/// What hovering over a place shows: markdown about the thing at `range`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct HoverResult {
    /// The hovered name or element.
    pub range: Span,
    pub markdown: String,
}

/// A place in some file of the workspace a query leads to (a mission, a
/// catalog file, a strategy file).
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct NavigationTarget {
    pub file: FileId,
    pub span: Span,
}

/// Edits of several files at once (a rename, an entry created in a strategy
/// file from its mission): per file, edits that do not overlap, in order.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct SourceChange {
    pub edits: Vec<(FileId, Vec<TextEdit>)>,
}

/// What a completion item is, for the editor's icon; one list for every kind
/// of file.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum CompletionKind {
    /// A built-in service of the catalog (`move`).
    BuiltinService,
    /// A function defined with `def`.
    Function,
    /// A robot value (`LOCATION`).
    Value,
    /// A team variable (`Alarm` of `publish(T, T.Alarm = DARK)`).
    TeamVariable,
    Team,
    /// The operator's console.
    User,
    RobotType,
    /// A robot of a team, by name.
    Robot,
    Capability,
    Plan,
    /// A composite service of a team.
    Service,
    Mode,
    Event,
    /// A symbolic constant (`DARK`, a value of an enumeration, `OFF`).
    Constant,
    /// A parameter of the function whose body the cursor is in.
    Parameter,
    /// An action result bound before the cursor in its body
    /// (`FOUND` of `FOUND, WHERE = search(red)`).
    Result,
    /// A time unit (`SEC`).
    Unit,
    Keyword,
    /// A construct's skeleton.
    Snippet,
    /// An XML element name.
    Element,
    /// An XML attribute name.
    Attribute,
    /// One of the fixed words an attribute takes (`Yes`, `channel`, `lowest_id`).
    Choice,
    /// A task of a robot (a strategy's `task`).
    Task,
    /// An action of a strategy service's action machine.
    Action,
    /// A task's port as a channel end (`task.port`).
    Port,
}

/// One completion: `insert` replaces `replace`. Made with [`CompletionItem::new`]
/// and the builder methods.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct CompletionItem {
    pub label: String,
    pub kind: CompletionKind,
    /// One line: a signature, a type.
    pub detail: Option<String>,
    /// Markdown.
    pub documentation: Option<String>,
    /// What replaces [`CompletionItem::replace`]: snippet syntax when
    /// `snippet`, plain text otherwise.
    pub insert: String,
    pub snippet: bool,
    /// The text being completed (empty at a fresh place).
    pub replace: Span,
}

impl CompletionItem {
    /// An item inserting its label as plain text.
    pub fn new(label: impl Into<String>, kind: CompletionKind, replace: Span) -> CompletionItem {
        let label = label.into();
        CompletionItem {
            insert: label.clone(),
            label,
            kind,
            detail: None,
            documentation: None,
            snippet: false,
            replace,
        }
    }

    pub fn detail(mut self, detail: impl Into<String>) -> CompletionItem {
        self.detail = Some(detail.into());
        self
    }

    /// Markdown documentation; an empty text is none.
    pub fn documentation(mut self, markdown: impl Into<String>) -> CompletionItem {
        let markdown = markdown.into();
        self.documentation = (!markdown.is_empty()).then_some(markdown);
        self
    }

    /// Inserts `text` (plain) instead of the label.
    pub fn insert(mut self, text: impl Into<String>) -> CompletionItem {
        self.insert = text.into();
        self.snippet = false;
        self
    }

    /// Inserts `snippet` (`${1:goal}` fields) instead of the label.
    pub fn snippet(mut self, snippet: impl Into<String>) -> CompletionItem {
        self.insert = snippet.into();
        self.snippet = true;
        self
    }
}

#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct CompletionConfig {
    /// Whether the editor understands snippets (`${1:goal}`).
    pub snippets: bool,
}

/// A refactoring offered at a place (not a fix of a diagnostic): its edits
/// may reach other files (an entry created in a strategy file from the
/// mission call at the cursor).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Assist {
    pub title: String,
    pub change: SourceChange,
}

/// What an outline entry or a workspace-search result is; one list for every
/// kind of file.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SymbolKind {
    Team,
    Robot,
    Plan,
    /// A composite service of a mission, or a strategy file's `<Service>`.
    Service,
    Mode,
    Main,
    Function,
    /// A strategy file's `<Value>`.
    Value,
    /// An action of a strategy service.
    Action,
    /// A name a mission's function or composite service binds to what a
    /// service call gives back (`FOUND, WHERE = search(red)`).
    Result,
}

/// One entry of a file's outline (document symbols), with the entries inside it.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct StructureNode {
    pub name: String,
    pub detail: Option<String>,
    pub kind: SymbolKind,
    /// The whole definition (for a team or a plan: from its first to its
    /// last item; in XML the whole element).
    pub span: Span,
    /// The name to select, inside `span`.
    pub name_span: Span,
    pub children: Vec<StructureNode>,
}

/// A symbol found by a workspace search.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct WorkspaceSymbol {
    pub name: String,
    pub kind: SymbolKind,
    /// `Team` for a mode, `Team.Plan` for a service.
    pub container: Option<String>,
    /// Its name.
    pub target: NavigationTarget,
    /// How well the name matches the query; lower is better
    /// (`mission::symbols::match_score`).
    pub score: u32,
}

/// What an inlay hint shows.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum InlayKind {
    /// The robots a mission's group arm selects.
    Robots,
    /// How the service a mission's mode sets runs.
    Schedule,
    /// A task graph's repetition count after a task's name.
    Repetitions,
}

/// A hint shown inside the text, before the character at `offset`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct InlayHint {
    pub offset: usize,
    pub label: String,
    pub kind: InlayKind,
    /// Markdown.
    pub tooltip: Option<String>,
}
