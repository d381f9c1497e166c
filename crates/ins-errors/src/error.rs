//! The crate's error type.

/// Every failure of this crate; each variant says where and what.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum InsError {
    /// A configuration field is out of its domain. `field` is the dotted TOML path, e.g.
    /// `imu.gyro_drift_sigma_degph` or `trajectory.segments[3].duration_s`.
    #[error("{field} {requirement}, got {value}")]
    InvalidConfig {
        /// Dotted path of the offending field.
        field: String,
        /// What the field must satisfy.
        requirement: String,
        /// The value found (formatted).
        value: String,
    },
    /// A TOML document or section could not be parsed into the config struct.
    #[error("TOML section [{section}]")]
    Toml {
        /// Section name (`trajectory`, `imu`).
        section: String,
        /// The loader's error: line, column and message (names the unknown or mistyped key);
        /// boxed, so that every `Result` carrying an `InsError` stays small.
        #[source]
        source: Box<toml_config::TomlError>,
    },
    /// A caller-owned buffer has the wrong length.
    #[error("{what}: buffer length {got}, expected {expected}")]
    BufferLength {
        /// Which buffer.
        what: &'static str,
        /// Required length.
        expected: usize,
        /// Length passed.
        got: usize,
    },
    /// A numeric argument is NaN/infinite or out of its domain.
    #[error("{func}: argument {arg} {requirement}, got {value}")]
    InvalidArgument {
        /// Function that rejected the argument.
        func: &'static str,
        /// Argument name.
        arg: &'static str,
        /// What it must satisfy.
        requirement: &'static str,
        /// The value found.
        value: String,
    },
}

impl InsError {
    pub(crate) fn config(
        field: impl Into<String>,
        requirement: &str,
        value: impl std::fmt::Debug,
    ) -> Self {
        Self::InvalidConfig {
            field: field.into(),
            requirement: requirement.to_string(),
            value: format!("{value:?}"),
        }
    }
}
