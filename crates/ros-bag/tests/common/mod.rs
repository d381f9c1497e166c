//! What the crate's property tests share.

use proptest::test_runner::{Config, RngSeed};

/// A proptest configuration with `cases` cases from the fixed `seed` and no failure files: the
/// same inputs on every run and machine.
pub fn seeded(cases: u32, seed: u64) -> Config {
    Config {
        cases,
        rng_seed: RngSeed::Fixed(seed),
        failure_persistence: None,
        ..Config::default()
    }
}
