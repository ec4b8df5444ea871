//! SeMo compiler library: mission scripts for teams of cooperating robots.
//!
//! Layers (each reads only the ones above it in this list):
//! - [`span`], [`text`], [`diag`], [`suggest`]: positions and diagnostics shared by all.
//! - [`syntax`]: lexer and parser (chumsky) from text to a positioned AST; never panics.
//! - [`catalog`]: robot types from the built-in catalog and `*.robot.xml` files.
//! - [`sema`]: name resolution and checks, producing the [`sema::Mission`] IR.
//! - [`strategy`]: strategy files (`*.strategy.xml`), checked on their own and
//!   against the catalog and the Mission IR.
//! - [`format`]: the canonical layout of mission scripts (`semo fmt`), from the
//!   tokens and the syntax tree.
//! - [`ide`]: editor features over an analysis (completion, hover, navigation, rename,
//!   outline, highlighting, folding, selection), as plain data in byte ranges.
//! - [`modemachine`]: each team's modes and mode changes, and their SVG picture.
//! - [`sim`]: the simulator: every robot's refined program run at once in
//!   virtual time on a scenario (`semo simulate`).
//! - [`workspace`]: loading files and folders from disk for the CLI.
//!
//! The `semo` command (rendering with ariadne or JSON) is the `semo-cli` crate
//! (`cli/`), above this library and the language server.

pub mod catalog;
pub mod codegen;
pub mod diag;
/// A fast deterministic hasher for the checker's maps.
mod fasthash;
pub mod format;
pub mod ide;
pub mod modemachine;
pub mod refine;
pub mod sema;
pub mod sim;
pub mod span;
pub mod strategy;
pub mod suggest;
pub mod syntax;
pub mod taskgraph;
pub mod text;
pub mod workspace;
/// Byte positions of XML elements and attributes, shared by the XML loaders.
mod xmlpos;
/// The positioned XML element tree read by the task-graph and strategy loaders.
mod xmltree;

pub use sema::{Analysis, check_source};
