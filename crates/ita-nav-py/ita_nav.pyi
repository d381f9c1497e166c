"""Lane-mark tracking of Pimentel & Hemerly (directional gradient -> Hough + least squares -> Kalman
information filter), from numpy. Built from the Rust crates of ita-nav (crates/ita-nav-py)."""

from typing import Literal, Optional, Tuple, TypedDict

import numpy as np
import numpy.typing as npt

__version__: str
DEFAULT_CONFIG_TOML: str
"""The default tracker configuration (configs/default.toml), every field with its unit."""

class NavError(Exception):
    """A configuration, frame or tracking error from the Rust library; the message names the field,
    file or frame."""

class Lane(TypedDict):
    side: Literal["left", "right"]
    state: Literal["initialising", "tracking", "coasting", "lost"]
    coeffs: Optional[Tuple[float, float, float]]
    """(a1, a2, a3) of x = a1*y**2 + a2*y + a3 (x column, y row, pixels of the frame), or None when
    the lane is initialising or lost."""
    rows: Tuple[float, float]
    """(y_min, y_max), rows (px) of the points behind the estimate."""
    points: int
    """Points used this frame (filter update, or the least-squares fit of an initialisation)."""
    initialised: bool
    """True if Hough + least squares (re-)initialised the lane on this frame."""
    covariance: Optional[npt.NDArray[np.float64]]
    """3 x 3 covariance of coeffs (pixel parameterisation), from the Kalman information filter's
    information matrix; None without an estimate."""

class EgoLane(TypedDict):
    """The ego lane on the ground plane (right/rightward positive), each with its standard deviation
    propagated from both lanes' covariances."""
    lateral_offset_m: float
    lateral_offset_m_sigma: float
    heading_rad: float
    heading_rad_sigma: float
    curvature_per_m: float
    curvature_per_m_sigma: float
    lane_width_m: float
    lane_width_m_sigma: float

class Counters(TypedDict):
    frames: int
    initialisations: Tuple[int, int]
    gated_jumps: Tuple[int, int]
    gated_crossings: Tuple[int, int]
    gated_pairs: int
    revalidations: int
    revalidation_switches: Tuple[int, int]
    set_asides: Tuple[int, int]
    lane_changes: int

class LaneTracker:
    """One tracker per video stream; every frame must have the size of the first one."""

    def __init__(
        self,
        config: Optional[str] = None,
        estimator: Literal["kif", "wrls"] = "kif",
        camera: Optional[str] = None,
    ) -> None:
        """config: None (the default configuration), a preset name ("default", "outdoor",
        "indoor") or a TOML file path. camera: None, a camera preset ("robot", "highway") or a
        camera TOML file (as nav-app --camera); with it, ego_lane gives the lane in metres.
        Raises NavError for a bad configuration or camera file (naming the file, line and field),
        ValueError for an unknown estimator."""
    def track(self, frame: npt.NDArray[np.uint8]) -> list[Lane]:
        """Track one frame: uint8 H x W (grey, read in place when C-contiguous) or H x W x 3 (RGB,
        converted with BT.601 luma). Returns [left, right]. Raises TypeError for another dtype or
        shape, ValueError for a non-contiguous array or a frame of another size, NavError for a
        frame the tracker refuses."""
    def reset(self) -> None:
        """Forget both lanes: the next frame initialises again."""
    @property
    def frame_shape(self) -> Optional[Tuple[int, int]]:
        """(height, width) of the frames this tracker takes, None before the first frame."""
    @property
    def last_track_us(self) -> float:
        """Wall time of the Rust tracker alone on the last frame, microseconds (NaN before any)."""
    @property
    def counters(self) -> Counters: ...
    @property
    def ego_lane(self) -> Optional[EgoLane]:
        """The ego lane in metres after the last frame (needs camera=); None unless both lanes
        are held."""

def read_frames(path: str) -> list[npt.NDArray[np.uint8]]:
    """Every frame of an input, read as `nav-app --input PATH` reads it: a YUV4MPEG2 file, a
    directory of images or a still image; H x W uint8 arrays. Raises NavError."""

FilterName = Literal["kf", "akf", "akf_sage_husa", "akf_structured"]

class UpdateReport(TypedDict):
    used: int
    rejected: int
    nis: Optional[float]
    adaptive_q: bool
    fed_back: bool

class Navigation(TypedDict):
    lat_rad: float
    lon_rad: float
    alt_m: float
    vel_ned_mps: Tuple[float, float, float]
    att_quat_wxyz: Tuple[float, float, float, float]

class InsSdFilter:
    """The online INS/sighting-device filter (crate ins-sd-filter): the same code the Monte Carlo
    and `nav-app ins` run."""

    def __init__(
        self,
        landmarks: str,
        initial: str,
        config: Optional[str] = None,
        filter: FilterName = "kf",
        gate: Optional[float] = None,
        filter_file: Optional[str] = None,
        preset: Optional[Literal["mems", "paper"]] = None,
        imu_step_s: float = 0.01,
    ) -> None:
        """landmarks: TOML landmark table; initial: TOML initial state (the formats export_run
        writes); config: a scenario file for the filter settings (None: the paper's), or instead
        filter_file (TOML in datasheet units, ins_sim::filter_file) / preset with the IMU's
        imu_step_s; filter "none" (or "standalone"): the unaided INS; gate: chi-square gate
        probability per sighting (None: no gate). Raises NavError naming the file."""
    def propagate_rates(
        self, t_s: float, specific_force_body_mps2: list[float], ang_rate_body_radps: list[float]
    ) -> None:
        """One IMU sample ending at t_s as mean rates over it, body FRD."""
    def update_pointed(
        self, t_s: float, sightings: list[Tuple[int, Literal["body", "ned"], float, float, float]]
    ) -> UpdateReport:
        """Sightings that carry their pointing (landmark_id, frame, x, y, z): the measured line of
        sight in body or local-level axes (sightings.csv format 2). A direction behind the camera
        counts as rejected."""
    def propagate(
        self, t_s: float, dv_body_mps: list[float], dtheta_body_rad: list[float]
    ) -> None:
        """One IMU sample ending at t_s: velocity and angle increments over it, body FRD.
        Raises NavError for out-of-order time or non-finite input, ValueError for a wrong length."""
    def update(self, t_s: float, sightings: list[Tuple[int, float, float]]) -> UpdateReport:
        """Sightings (landmark_id, w_m, h_m) at the epoch t_s (the INS time); 0 to many."""
    @property
    def time_s(self) -> float: ...
    @property
    def error_state(self) -> npt.NDArray[np.float64]:
        """15 error states: dp (m NED), dv (m/s NED), psi (rad), accel bias (m/s^2), gyro drift (rad/s)."""
    @property
    def covariance(self) -> Optional[npt.NDArray[np.float64]]:
        """15 x 15 error covariance."""
    def navigation(self) -> Navigation:
        """The corrected navigation solution."""
    @property
    def statistics(self) -> dict[str, int]:
        """imu_samples, epochs, sightings_used, sightings_rejected, adaptive_q_used."""

def export_run(
    out_dir: str,
    config: Optional[str] = None,
    filter: Literal["standalone"] | FilterName = "kf",
    seed: int = 0,
) -> int:
    """Simulate one flight and write its logs (imu.csv, sightings.csv, truth.csv, landmarks.toml,
    initial.toml, scenario.toml, solution.csv) into out_dir; returns the records written."""

def replay(
    imu: str,
    out: str,
    sightings: Optional[str] = None,
    landmarks: Optional[str] = None,
    initial: Optional[str] = None,
    truth: Optional[str] = None,
    start_s: Optional[float] = None,
    filter: Literal["none"] | FilterName = "kf",
    filter_file: Optional[str] = None,
    preset: Optional[Literal["mems", "paper"]] = None,
    gate: Optional[float] = None,
    align_s: float = 0.0,
    max_gap_s: float = 5.0,
    rate_hz: Optional[float] = None,
    imu_topic: Optional[str] = None,
    allow_unaided: bool = False,
) -> dict:
    """Replay an IMU log as `nav-app ins` does; returns imu_samples, epochs, sightings_used,
    sightings_rejected, lead_in_s (from the start to the first IMU sample, s: not a gap), gaps,
    longest_gap_s, end_t_s and, with truth, metrics (as --metrics-json).
    Inputs that do not overlap in time, a filter that used no sighting (unless allow_unaided) and
    an alignment (align_s) away from rest raise NavError naming the files and their spans."""

def write_sightings(
    reference: str,
    landmarks: str,
    out: str,
    sigma_m: float = 1.0,
    period_s: float = 1.0,
    max_range_m: float = 1000.0,
    max_per_epoch: int = 6,
    field_of_regard_deg: float = 180.0,
    make_landmarks: Optional[int] = None,
    landmark_range_m: Tuple[float, float] = (50.0, 300.0),
    seed: int = 1,
) -> dict:
    """Write pointed sightings from a reference trajectory (nav-app ins sightings); with
    make_landmarks, place that many landmarks around it first and write them to `landmarks`."""

def run_flight(
    config: Optional[str] = None,
    filter: Literal["standalone"] | FilterName = "kf",
    seed: int = 0,
) -> dict[str, npt.NDArray[np.float64]]:
    """One simulated flight as numpy arrays: t_s, pos_err_ned_m (n x 3), vel_err_ned_mps,
    misalignment_rad, distance_m, nees and nis (NaN off the sighting epochs)."""

class ModeResult(TypedDict):
    runs_used: int
    excluded: list[dict]
    """Runs left out: run_index, t_s, reason."""
    rms_pos_3d_m: npt.NDArray[np.float64]
    rms_pos_h_m: npt.NDArray[np.float64]
    rms_pos_d_m: npt.NDArray[np.float64]
    mean_nees: npt.NDArray[np.float64]
    mean_nis: npt.NDArray[np.float64]
    final_rms_pos_3d_m: float
    final_rms_pos_h_m: float
    final_rms_pos_d_m: float
    final_pos_3d_m: npt.NDArray[np.float64]

class MonteCarloResult(TypedDict):
    runs: int
    seed: int
    t_s: npt.NDArray[np.float64]
    modes: dict[str, ModeResult]

def monte_carlo(
    config: Optional[str] = None,
    runs: Optional[int] = None,
    seed: Optional[int] = None,
    filters: Optional[list[str]] = None,
) -> MonteCarloResult:
    """The Monte Carlo (config None: the paper's scenario; runs and seed default to the scenario's;
    filters default to standalone, kf, akf): the same runs and statistics as `cargo xtask
    monte-carlo`, as numpy series per second (RMS over runs, mean NEES/NIS) and final figures."""
