//! SeMo compiler library: mission scripts for teams of cooperating robots.
//!
//! The modules are layered: each reads only the modules below it in the
//! `## Layers` table of ARCHITECTURE.md, which `tests/layering.rs` checks
//! against every `crate::` path. From the bottom: positions and diagnostics
//! ([`span`], [`text`], [`diag`], [`edit`]) and the platforms programs are
//! built for ([`platform`], a data table); the languages ([`syntax`],
//! [`format`], [`catalog`], [`sema`], [`taskgraph`], [`strategy`]); what is
//! made of them ([`modemachine`], [`ide`], [`refine`], [`codegen`]);
//! [`sim`], the simulator running the refined programs of a mission on a
//! scenario; [`workspace`], which reads files from disk; and on top
//! [`host`], the one workspace analysis the command line and the language
//! server both ask.
//!
//! The `semo` command (rendering with ariadne or JSON) is the `semo-cli` crate
//! (`cli/`), above this library and the language server.

pub mod catalog;
pub mod codegen;
pub mod dataflow;
pub mod deploy;
pub mod diag;
mod digraph;
pub mod edit;
/// A fast deterministic hasher for the checker's maps.
mod fasthash;
pub mod format;
pub mod fsread;
pub mod host;
pub mod ide;
/// Typed indices (`newtype_index!`): a plan's index is not a mode's.
mod index;
/// Graph drawing shared by the task-graph and mode-machine pictures.
mod layout;
pub mod modemachine;
pub mod platform;
pub mod project;
pub mod refine;
pub mod sema;
pub mod sim;
pub mod span;
pub mod strategy;
pub mod suggest;
pub mod syntax;
pub mod targets;
pub mod taskgraph;
pub mod text;
pub mod verify;
pub mod workspace;
/// Byte positions of XML elements and attributes, shared by the XML loaders.
mod xmlpos;
/// The positioned XML element tree read by the task-graph and strategy loaders.
mod xmltree;

pub use sema::{CheckedMission, check_source};
