//! A mission's refined programs as one memoised query of the workspace
//! analysis: every door asks for it instead of refining the mission on its
//! own (`semo build` and the editor's Generate Code through `build::generate`;
//! `semo simulate`, `verify` and `replay`; the monitor, the operator console,
//! deployment, the server's simulate and verify, scenario completion, the
//! task-graph picture), and a second request on the same files refines
//! nothing.

use super::{Analysis, drop_later, fresh, lock};
use crate::diag::FileId;
use crate::refine::Refined;
use crate::workspace::FileKind;
use std::sync::Arc;

impl Analysis {
    /// The mission's refined programs (`refine::refine_checked` of its
    /// [`Analysis::build_input`]), or their refusal with its diagnostics;
    /// `None` for a file that is not a mission of the workspace.
    pub fn refined(&self, mission: FileId) -> Option<Arc<Refined>> {
        self.file(mission).filter(|f| f.kind == FileKind::Mission)?;
        let key = self.reads_key(mission);
        if let Some(found) = fresh(lock(&self.memo.refined).get(&mission), &key) {
            return Some(found);
        }
        let build = self.build_input(mission)?;
        let found = Arc::new(crate::refine::refine_checked(&build.input()));
        let old = lock(&self.memo.refined).insert(mission, (key, found.clone()));
        drop_later(old);
        Some(found)
    }
}
