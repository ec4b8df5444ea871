//! The editor's facade: position queries on an [`Analysis`] snapshot. Each
//! finds the file's kind, gathers what that kind's features in
//! [`crate::ide`] read from this snapshot (the checked mission, the catalog
//! the file sees, the missions a strategy file is checked against, a task
//! graph's report) and answers in [`crate::ide`]'s vocabulary. A door asks
//! these, never `ide::mission`/`ide::strategy`/`ide::taskgraph` directly, so
//! every door and every file kind reads the same workspace.
//!
//! Adding a kind of file: a submodule of `ide`, then one arm per query here.

use super::Analysis;
use crate::diag::FileId;
use crate::ide::{
    self, CompletionConfig, CompletionItem, CompletionKind, FilePosition, Fold, HoverResult,
    NavigationTarget, Reference, RenameError, SignatureHelp, SourceChange, TextEdit,
    strategy::StrategyFile,
};
use crate::sema;
use crate::workspace::FileKind;
use std::sync::Arc;

impl Analysis {
    /// What hovering at `position` shows.
    pub fn hover(&self, position: FilePosition) -> Option<HoverResult> {
        let FilePosition { file, offset } = position;
        match self.file(file)?.kind {
            FileKind::Mission => {
                let text = &self.file(file)?.text;
                let mission = self.mission(file)?;
                let catalog = self.catalog(file);
                let mut found =
                    ide::mission::hover::hover(&mission, &catalog.catalog, text, offset)?;
                // On a team: its robots' iteration periods (refines the
                // mission once per version; the server's diagnostics task
                // usually has already).
                let periods = crate::dataflow::team_periods_at(&mission.mission, offset, || {
                    self.dataflow(file)
                });
                if let Some(periods) = periods {
                    found.markdown.push_str("\n\n---\n\n");
                    found.markdown.push_str(&periods);
                }
                Some(found)
            }
            FileKind::Strategy => {
                self.with_strategy(file, |s| ide::strategy::hover::hover(s, offset))
            }
            FileKind::TaskGraph => {
                let run = self.graph(file)?;
                ide::taskgraph::hover(run.graph.as_ref()?, &run.report, offset)
            }
            FileKind::Catalog | FileKind::Project => None,
        }
    }

    /// What may be written at `position`, most specific first; `None` where
    /// the file has no completion at all (a catalog file, a task graph that
    /// does not load).
    pub fn completions(
        &self,
        position: FilePosition,
        config: CompletionConfig,
    ) -> Option<Vec<CompletionItem>> {
        let FilePosition { file, offset } = position;
        let source = self.file(file)?;
        match source.kind {
            FileKind::Mission => {
                let mission = self.mission(file)?;
                let catalog = self.catalog(file);
                Some(ide::mission::completion::completions(
                    &mission,
                    &catalog.catalog,
                    &source.text,
                    offset,
                    config,
                ))
            }
            FileKind::Strategy => Some(self.with_strategy(file, |s| {
                ide::strategy::completion::completions(s, offset, config.snippets)
            })),
            FileKind::TaskGraph => {
                let run = self.graph(file)?;
                let graph = run.graph.as_ref()?;
                Some(ide::taskgraph::complete_endpoint(
                    &source.text,
                    graph,
                    offset,
                ))
            }
            FileKind::Project => Some(
                crate::project::completions(&source.text, offset, &self.project_names(file))
                    .into_iter()
                    .map(project_completion)
                    .collect(),
            ),
            FileKind::Catalog => None,
        }
    }

    /// Where the name at `position` is defined. In a mission: from a built-in
    /// call, the strategy entries refining it first, then its definition (in
    /// the mission or a catalog file). In a strategy file: the mission lines
    /// an entry refines, the team, plan or robot type it names.
    pub fn definition(&self, position: FilePosition) -> Vec<NavigationTarget> {
        let FilePosition { file, offset } = position;
        let Some(source) = self.file(file) else {
            return Vec::new();
        };
        match source.kind {
            FileKind::Mission => {
                let Some(mission) = self.mission(file) else {
                    return Vec::new();
                };
                let catalog = self.catalog(file);
                let mut found = self.entries_of_call(position);
                found.extend(ide::mission::navigation::definition(
                    &mission,
                    &catalog.catalog,
                    offset,
                ));
                found
            }
            FileKind::Strategy => {
                let links = self.strategy_links(file);
                self.with_strategy(file, |s| {
                    ide::strategy::navigation::definition(s, &links, offset)
                })
            }
            FileKind::TaskGraph | FileKind::Catalog | FileKind::Project => Vec::new(),
        }
    }

    /// Every place meaning what the name at `position` means: in a mission,
    /// its names (definitions only if `include_declaration`); in a strategy
    /// file, the mission lines an entry refines or reads.
    pub fn references(
        &self,
        position: FilePosition,
        include_declaration: bool,
    ) -> Vec<NavigationTarget> {
        let FilePosition { file, offset } = position;
        let Some(source) = self.file(file) else {
            return Vec::new();
        };
        match source.kind {
            FileKind::Mission => {
                let Some(mission) = self.mission(file) else {
                    return Vec::new();
                };
                ide::mission::navigation::references(&mission, offset)
                    .into_iter()
                    .filter(|r| include_declaration || !r.is_definition)
                    .map(|r| NavigationTarget { file, span: r.span })
                    .collect()
            }
            FileKind::Strategy => {
                let links = self.strategy_links(file);
                self.with_strategy(file, |s| {
                    ide::strategy::navigation::references(s, &links, offset, include_declaration)
                })
            }
            FileKind::TaskGraph | FileKind::Catalog | FileKind::Project => Vec::new(),
        }
    }

    /// Renaming the name at `position` to `new_name`: the edits (a mission is
    /// self-contained, so all in it), or why the rename is refused. `None`
    /// where renaming means nothing (other kinds of file).
    pub fn rename(
        &self,
        position: FilePosition,
        new_name: &str,
    ) -> Option<Result<SourceChange, RenameError>> {
        let FilePosition { file, offset } = position;
        let source = self.file(file).filter(|f| f.kind == FileKind::Mission)?;
        let mission = self.mission(file)?;
        let catalog = self.catalog(file);
        let spans = ide::mission::rename::rename(
            &mission,
            &catalog.catalog,
            &source.text,
            offset,
            new_name,
        );
        Some(spans.map(|spans| SourceChange {
            edits: vec![(
                file,
                spans
                    .into_iter()
                    .map(|span| TextEdit {
                        span,
                        new_text: new_name.to_string(),
                    })
                    .collect(),
            )],
        }))
    }

    /// The signature of the call around `position` (missions only).
    pub fn signature_help(&self, position: FilePosition) -> Option<SignatureHelp> {
        let FilePosition { file, offset } = position;
        let source = self.file(file).filter(|f| f.kind == FileKind::Mission)?;
        let mission = self.mission(file)?;
        let catalog = self.catalog(file);
        ide::mission::signature_help::signature_help(
            &mission,
            &catalog.catalog,
            &source.text,
            offset,
        )
    }

    /// From a mission's built-in call at `position` to the entries of the
    /// strategy files it sees that refine it.
    fn entries_of_call(&self, position: FilePosition) -> Vec<NavigationTarget> {
        let mut out = Vec::new();
        for strategy_file in self.seen_by(position.file) {
            let Some(loaded) = self.strategy(strategy_file) else {
                continue;
            };
            let Some(model) = &loaded.strategy else {
                continue;
            };
            let links = self.strategy_links(strategy_file);
            let spans = ide::strategy::navigation::entries_of_call(
                model,
                &links,
                position.file,
                position.offset,
            );
            out.extend(spans.into_iter().map(|span| NavigationTarget {
                file: strategy_file,
                span,
            }));
        }
        out
    }

    /// The ranges a file folds into (blocks, `case`s, group statements,
    /// comment banners); empty for other kinds of files.
    pub fn folding_ranges(&self, file: FileId) -> Vec<Fold> {
        match self.mission_of_kind(file) {
            Some((mission, text)) => ide::mission::folding::folding_ranges(&mission, text),
            None => Vec::new(),
        }
    }

    /// The ranges holding `position`, innermost first (from the name outward
    /// to the whole file); empty for other kinds of files.
    pub fn selection_ranges(&self, position: FilePosition) -> Vec<crate::span::Span> {
        let FilePosition { file, offset } = position;
        match self.mission_of_kind(file) {
            Some((mission, text)) => {
                ide::mission::selection::selection_ranges(&mission, text, offset)
            }
            None => Vec::new(),
        }
    }

    /// The names in the file meaning the symbol at `position`, each a read
    /// or a write (definitions, throws, assigned team variables).
    pub fn highlights(&self, position: FilePosition) -> Vec<Reference> {
        let FilePosition { file, offset } = position;
        match self.mission_of_kind(file) {
            Some((mission, _)) => ide::mission::navigation::references(&mission, offset),
            None => Vec::new(),
        }
    }

    /// A mission file's checked mission and text; `None` for other files.
    pub(super) fn mission_of_kind(
        &self,
        file: FileId,
    ) -> Option<(Arc<sema::CheckedMission>, &str)> {
        let source = self.file(file).filter(|f| f.kind == FileKind::Mission)?;
        Some((self.mission(file)?, &source.text))
    }

    /// Runs `f` on the strategy file `file` as its features read it: its
    /// text and model, the missions that see it (checked), its catalog.
    fn with_strategy<T: Default>(&self, file: FileId, f: impl FnOnce(&StrategyFile<'_>) -> T) -> T {
        let Some(source) = self.file(file) else {
            return T::default();
        };
        let loaded = self.strategy(file);
        let checked: Vec<Arc<sema::CheckedMission>> = self
            .missions_seeing(file)
            .into_iter()
            .filter_map(|m| self.mission(m))
            .collect();
        let missions: Vec<&sema::CheckedMission> = checked.iter().map(|m| &**m).collect();
        let catalog = self.catalog(file);
        f(&StrategyFile {
            text: &source.text,
            strategy: loaded.as_ref().and_then(|l| l.strategy.as_ref()),
            missions: &missions,
            catalog: &catalog.catalog,
        })
    }
}

mod edits;
mod structure;
#[cfg(test)]
mod tests;

pub use structure::{PictureError, RobotPicture, WORKSPACE_SYMBOL_LIMIT};

/// A `semo.toml` completion in the editor vocabulary.
fn project_completion(item: crate::project::Completion) -> CompletionItem {
    use crate::project::CompletionKind as P;
    let kind = match item.kind {
        P::Table => CompletionKind::Element,
        P::Key => CompletionKind::Attribute,
        P::Code => CompletionKind::Constant,
        P::Value => CompletionKind::Value,
    };
    let mut out = CompletionItem::new(item.label, kind, item.replace).detail(item.detail);
    out.insert = item.insert;
    out
}
