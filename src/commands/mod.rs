//! The commands that run one experiment from its file: each reads the experiment, runs the
//! study (`stf_study`), writes the typed result's folder ([`crate::results`]) and says where
//! it went. Nothing here decides anything about the science. `campaign` is
//! [`crate::campaign::command`]: its units run the same study calls and writers.

pub mod compare;
pub mod discover;
pub mod fit;
pub mod models;
pub mod simulate;
