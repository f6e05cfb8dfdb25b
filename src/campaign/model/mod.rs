//! What a campaign is: the validated [`Campaign`](campaign::Campaign) with its problems
//! (`campaign.rs`), its TOML file (`spec.rs`), and its expansion into jobs with their ids
//! (`jobs.rs`).
pub(crate) mod campaign;
pub(crate) mod jobs;
pub(crate) mod spec;
