//! What a campaign keeps: a job's record (a journal line, `record.rs`), the journal
//! (`journal.rs`), the claims that coordinate processes sharing a results folder (`claims.rs`),
//! and the split of the jobs into shards (`shard.rs`).
pub(crate) mod claims;
pub(crate) mod journal;
pub(crate) mod record;
pub(crate) mod shard;
