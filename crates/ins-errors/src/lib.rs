//! Strapdown INS error analysis (crate doc completed below).

pub mod config;
pub mod earth;
pub mod error;
pub mod error_model;
pub mod imu;
pub mod strapdown;
pub mod trajectory;

pub use error::InsError;
