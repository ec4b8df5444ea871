//! The SeMo language server (grows in the language-server issue). This crate
//! also builds the `semo` binary, since the server depends on the compiler
//! library and the binary serves both.
