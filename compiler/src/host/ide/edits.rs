//! The facade's queries that change text: quick fixes, assists, the range a
//! rename starts from, formatting.

use crate::diag::{Diagnostic, FileId};
use crate::format::FormatRefusal;
use crate::host::Analysis;
use crate::ide::{self, Assist, CodeAction, FilePosition, RenameError, SourceChange, TextEdit};
use crate::span::Span;
use crate::workspace::FileKind;

impl Analysis {
    /// The quick fixes of the file's diagnostics that touch `range`; each
    /// action's `diagnostic` is an index into [`Analysis::diagnostics`] of
    /// that file (what every door publishes), so a fix is offered only for a
    /// diagnostic the user sees.
    pub fn code_actions(&self, file: FileId, range: Span) -> Vec<CodeAction> {
        let Some(source) = self.file(file) else {
            return Vec::new();
        };
        let published = self.diagnostics(file);
        match source.kind {
            FileKind::Mission => {
                let Some(mission) = self.mission(file) else {
                    return Vec::new();
                };
                let catalog = self.catalog(file);
                let actions = ide::mission::code_actions::code_actions(
                    &mission,
                    &catalog.catalog,
                    &source.text,
                    range,
                );
                // The checker's diagnostics are a part of the published
                // ones (with the units' and the lints' changes): re-point
                // each fix at its diagnostic there.
                actions
                    .into_iter()
                    .filter_map(|mut action| {
                        let ours = mission.diagnostics.get(action.diagnostic)?;
                        action.diagnostic = published.iter().position(|d| same(d, ours))?;
                        Some(action)
                    })
                    .collect()
            }
            FileKind::Strategy => {
                ide::strategy::code_actions::code_actions(&source.text, &published, range)
            }
            FileKind::TaskGraph | FileKind::Catalog | FileKind::Project => Vec::new(),
        }
    }

    /// The refactorings offered at `position`: in a mission, on a built-in
    /// call, creating its entry in each strategy file the mission sees whose
    /// team runs it and that does not refine it yet.
    pub fn assists(&self, position: FilePosition) -> Vec<Assist> {
        let FilePosition { file, offset } = position;
        let Some((mission, _)) = self.mission_of_kind(file) else {
            return Vec::new();
        };
        let catalog = self.catalog(file);
        let mut out = Vec::new();
        for strategy_file in self.seen_by(file) {
            let (Some(loaded), Some(source)) =
                (self.strategy(strategy_file), self.file(strategy_file))
            else {
                continue;
            };
            let Some(model) = &loaded.strategy else {
                continue;
            };
            let links = self.strategy_links(strategy_file);
            let Some(found) = ide::strategy::code_actions::create_entry(
                &mission,
                &catalog.catalog,
                offset,
                model,
                &source.text,
                &links,
            ) else {
                continue;
            };
            out.push(Assist {
                title: found.title,
                change: SourceChange {
                    edits: vec![(strategy_file, vec![found.edit])],
                },
            });
        }
        out
    }

    /// The name a rename at `position` would change, or why it cannot be
    /// renamed (a catalog name, a constant, a keyword); `None` in files
    /// where renaming means nothing.
    pub fn prepare_rename(&self, position: FilePosition) -> Option<Result<Span, RenameError>> {
        let (mission, text) = self.mission_of_kind(position.file)?;
        Some(ide::mission::rename::prepare_rename(
            &mission,
            text,
            position.offset,
        ))
    }

    /// The edits giving a mission `semo fmt`'s layout, or why it is left as
    /// it is; `None` for other kinds of files (they have no formatter).
    pub fn formatting(&self, file: FileId) -> Option<Result<Vec<TextEdit>, FormatRefusal>> {
        let source = self.file(file).filter(|f| f.kind == FileKind::Mission)?;
        Some(ide::mission::formatting::formatting(&source.text))
    }
}

/// The same finding: what a fix computed from the checker's diagnostics
/// matches among the published ones.
fn same(a: &Diagnostic, b: &Diagnostic) -> bool {
    a.code == b.code && a.span == b.span && a.message == b.message
}
