//! SeMo compiler library: mission scripts for teams of cooperating robots.
//!
//! The modules are layered: each reads only the modules below it in the
//! `## Layers` table of ARCHITECTURE.md, which `tests/layering.rs` checks
//! against every `crate::` path. From the bottom: positions and diagnostics
//! ([`span`], [`text`], [`diag`], [`edit`]), the platforms programs are
//! built for ([`platform`], a data table) and which each robot of a build is
//! for ([`targets`]); the languages ([`syntax`], [`format`], [`catalog`],
//! [`sema`], [`taskgraph`], [`strategy`]); what is made of them
//! ([`modemachine`], [`ide`], [`refine`]); [`workspace`], which reads files
//! from disk; [`host`], the one workspace analysis the command line and the
//! language server both ask; the two back ends over the refined programs,
//! [`codegen`] (C) and [`sim`] (the simulator running them on a scenario),
//! neither reading the other; and on top [`build`], one build of a mission
//! (a scenario compiled in) for every door.
//!
//! The `semo` command (rendering with ariadne or JSON) is the `semo-cli` crate
//! (`cli/`), above this library and the language server.

pub mod build;
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
pub mod link;
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
