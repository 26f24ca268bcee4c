//! A study result's folder: the files of a fit, a comparison or a discovery (JSON from the
//! study's `Serialize` types, CSV tables, the documents) written from the typed result into a
//! staging folder, and the result's summary on the terminal. The commands
//! ([`crate::commands`]) and campaign units ([`crate::campaign::unit`]) both run the study
//! and then write here; nothing here decides anything about the science.

pub mod compare;
pub mod discover;
pub mod fit;
pub mod shown;
