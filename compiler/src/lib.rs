//! SeMo compiler library: mission scripts for teams of cooperating robots.
//!
//! Layers (each reads only the ones above it in this list):
//! - [`span`], [`text`], [`diag`], [`suggest`]: positions and diagnostics shared by all.
//! - [`syntax`]: lexer and parser (chumsky) from text to a positioned AST; never panics.
//! - [`catalog`]: robot types from the built-in catalog and `*.robot.xml` files.
//! - [`sema`]: name resolution and checks, producing the [`sema::Mission`] IR.
//! - [`ide`]: editor features over an analysis (navigation, rename, outline,
//!   highlighting, folding, selection), in byte ranges, for the language server.
//! - [`workspace`]: loading files and folders from disk for the CLI.
//! - [`cli`]: the `semo` command (rendering with ariadne or JSON).

pub mod catalog;
pub mod cli;
pub mod diag;
pub mod ide;
pub mod sema;
pub mod span;
pub mod suggest;
pub mod syntax;
pub mod taskgraph;
pub mod text;
pub mod workspace;
/// Byte positions of XML elements and attributes, shared by the XML loaders.
mod xmlpos;

pub use sema::{Analysis, check_source};
