//! Where the third-party evaluation data lives. It is never part of the repository (it is not ours
//! to redistribute): it is read from a data root, `../shared/data` beside the checkout by default
//! or the directory named by the environment variable `ITA_NAV_DATA`, and a missing file is an
//! error that says what is missing and where it was looked for. A test that needs it uses
//! [`test_data_file`]: missing data fails it under CI and skips it, saying so, elsewhere.

use std::path::{Path, PathBuf};

use crate::BenchError;

/// Environment variable naming the data root (instead of `../shared/data` beside the checkout).
pub const DATA_ENV: &str = "ITA_NAV_DATA";

/// The real udacity clip (221 frames, 320×240 grey YUV4MPEG2), relative to the data root.
pub const UDACITY_CLIP: &str = "udacity/solidWhiteRight-320x240-gray.y4m";

/// The labelled real lane sets, relative to the data root.
pub const LANE_SETS: &str = "lanes";

/// The data root: `$ITA_NAV_DATA`, else `<workspace>/../shared/data`.
pub fn data_root() -> PathBuf {
    match std::env::var_os(DATA_ENV) {
        Some(dir) => PathBuf::from(dir),
        None => Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data"),
    }
}

/// `relative` under the data root, or [`BenchError::MissingData`] naming it.
pub fn data_file(relative: &str) -> Result<PathBuf, BenchError> {
    let path = data_root().join(relative);
    if path.exists() {
        Ok(path)
    } else {
        Err(BenchError::MissingData {
            path: path.display().to_string(),
            what: relative.to_owned(),
        })
    }
}

/// Environment variable whose presence marks a CI run (set by every CI service): there, missing
/// test data is a failure, not a skip.
pub const CI_ENV: &str = "CI";

/// For a test that needs `relative` (under the data root): `Ok(Some(path))` when it is there.
/// When it is not: under CI (`$CI` set) [`BenchError::MissingData`] naming it, for the test to
/// fail with; elsewhere `Ok(None)` after `SKIPPED: …` naming it on stderr, for the test to
/// return early.
///
/// # Errors
/// [`BenchError::MissingData`] under CI when `relative` is missing.
pub fn test_data_file(relative: &str) -> Result<Option<PathBuf>, BenchError> {
    match data_file(relative) {
        Ok(path) => Ok(Some(path)),
        Err(e) if std::env::var_os(CI_ENV).is_some() => Err(e),
        Err(e) => {
            eprintln!("SKIPPED (outside CI): {e}");
            Ok(None)
        }
    }
}
