//! Test-only: the `campaign` command line with the deterministic fake runner
//! (`hinfix::campaign::FakeRunner`) in place of the design, for the machinery tests (tests/campaign_runner.rs,
//! campaign_shared.rs, reliability.rs), which find it next to their own executable
//! (tests/common/mod.rs, `fake_campaign_bin`). It needs the `test-support` feature, which the
//! crate's dev-dependency on itself turns on: `cargo test` builds it; `cargo build` and
//! `cargo install` do not. The pause between fake iterations is read from
//! `HINFIX_FAKE_RUNNER` (milliseconds; default 20).
use hinfix::campaign::FakeRunner;

fn main() -> std::process::ExitCode {
    hinfix::cli::main_with(Some(FakeRunner::from_env()))
}
