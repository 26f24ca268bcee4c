//! The commands that run one experiment: each reads the experiment (or takes a campaign
//! unit's), runs the study (`stf_study`), writes the typed result's files and renders its
//! documents. Nothing here decides anything about the science. `campaign` is
//! [`crate::campaign::command`]: it runs these for each of its units.

pub mod compare;
pub mod discover;
pub mod fit;
pub mod models;
pub mod simulate;
