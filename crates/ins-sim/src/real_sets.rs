//! How the real IMU logs under the data root (`ins/<set>/{imu,truth}.csv`, third-party, never
//! in the repository) are replayed: the choices that depend on the platform, not on the filter.
//! Used by the real-log test (`tests/ins_real_logs.rs`) and `cargo xtask ins-real`.

/// The replay recipe of one real log.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RealSet {
    /// Directory name under `ins/`.
    pub name: &'static str,
    /// Start of the replay, s (`None`: the reference's first row).
    pub start_s: Option<f64>,
    /// The platform is at rest for this long after the start, s (static alignment).
    pub align_s: f64,
    /// Landmarks placed around the trajectory at these horizontal distances, m.
    pub landmark_range_m: (f64, f64),
    /// Landmarks placed.
    pub landmarks: usize,
    /// Farthest landmark sighted, m.
    pub max_range_m: f64,
}

/// The two logs of `../shared/data/ins`: EuRoC MH_01 (a hexacopter in a machine hall: hand-moved
/// for 20 s, at rest 20.4–43.7 s, landmarks on the hall's scale) and rtkexplorer's drive of
/// 2025-07-08 (a car at rest for 34 s, then streets: landmarks at street distances).
pub const REAL_SETS: [RealSet; 2] = [
    RealSet {
        name: "euroc_mh01",
        start_s: Some(21.0),
        align_s: 20.0,
        landmark_range_m: (5.0, 20.0),
        landmarks: 12,
        max_range_m: 40.0,
    },
    RealSet {
        name: "rtkexp_drive0708",
        start_s: None,
        align_s: 30.0,
        landmark_range_m: (30.0, 200.0),
        landmarks: 60,
        max_range_m: 500.0,
    },
];

/// The seed of the landmark placement and the sighting noise.
pub const REAL_SEED: u64 = 7;
