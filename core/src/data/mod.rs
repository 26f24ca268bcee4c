//! Data: records of the rig and what is read from them — reading and writing records under a
//! size cap, their kinematics, the STF force recovered from them, a first estimate of a shaker
//! rig's oscillator, parameter bounds that follow a record, and summaries of a response.

pub mod bounded;
pub mod estimate;
pub mod force_data;
pub mod kinematics;
pub mod memory;
pub mod record;
pub mod record_bounds;
pub mod recover;
pub mod response;
