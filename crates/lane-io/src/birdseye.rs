//! Bird's-eye (inverse perspective) view: the ground plane seen from above, resampled from the
//! camera frame through the ground-plane homography, with the tracked lanes and the ego-lane
//! model drawn on it.
//!
//! The view covers `X ∈ [0, 2·far]` forward (up the picture) and `Y ∈ [−far, far]` across
//! (right is right), `far` the camera file's `lookahead.far_m`, at 320×320 px. Grey:
//! the camera frame where the ground is visible, dark blue elsewhere. Red / blue dots: the left
//! and right lanes as reported, mapped to the ground row by row over the rows each is seen on
//! (`LaneReport::rows`, the far segment above its join). Green:
//! the ego-lane model (centre line dashed, the two marks solid) over the look-ahead range,
//! from `lateral_offset_m`, `heading_rad`, `curvature_per_m` and `lane_width_m`. Yellow ticks:
//! the look-ahead range's ends. The camera is at the bottom centre.

use lane_tracker::camera::{CameraModel, EgoLaneReport};
use lane_tracker::{GreyFrame, TrackReport};

use crate::LaneIoError;

const SIZE_PX: usize = 320;
const OFF_GROUND_RGB: [u8; 3] = [20, 24, 48];
const LANE_RGB: [[u8; 3]; 2] = [[255, 40, 40], [60, 110, 255]];
const MODEL_RGB: [u8; 3] = [40, 230, 60];
const RANGE_RGB: [u8; 3] = [255, 220, 0];

/// A bird's-eye renderer for one camera; the source-pixel table is built once.
#[derive(Debug, Clone)]
pub struct BirdseyeView {
    camera: CameraModel,
    x_max_m: f64,
    y_half_m: f64,
    /// For each view pixel, the camera-frame pixel index it samples, or `u32::MAX` off the ground
    /// or outside the frame.
    source: Vec<u32>,
}

impl BirdseyeView {
    /// The view for `camera` (frames of its `image_size_px`).
    ///
    /// # Errors
    /// None today; reserved for cameras whose view cannot be built.
    pub fn for_camera(camera: &CameraModel) -> Result<Self, LaneIoError> {
        let far = camera.config().lookahead.far_m;
        let (x_max_m, y_half_m) = (2.0 * far, far);
        let [w, h] = camera.config().image_size_px;
        let hom = camera.homography();
        let mut source = vec![u32::MAX; SIZE_PX * SIZE_PX];
        for (i, s) in source.iter_mut().enumerate() {
            let (r, c) = (i / SIZE_PX, i % SIZE_PX);
            let x = x_max_m * (1.0 - (r as f64 + 0.5) / SIZE_PX as f64);
            let y = y_half_m * (2.0 * (c as f64 + 0.5) / SIZE_PX as f64 - 1.0);
            if let Ok([u, v]) = hom.ground_to_image([x, y]) {
                let (u, v) = (u.round(), v.round());
                if u >= 0.0 && v >= 0.0 && (u as usize) < w && (v as usize) < h {
                    *s = (v as usize * w + u as usize) as u32;
                }
            }
        }
        Ok(Self {
            camera: *camera,
            x_max_m,
            y_half_m,
            source,
        })
    }

    /// Write `rgb` (as filled by [`BirdseyeView::render`]) as a PNG file at `path`.
    ///
    /// # Errors
    /// [`LaneIoError::WriteImage`] naming the file.
    pub fn write_png(&self, path: &std::path::Path, rgb: &[u8]) -> Result<(), LaneIoError> {
        image::save_buffer(
            path,
            rgb,
            self.width_px() as u32,
            self.height_px() as u32,
            image::ExtendedColorType::Rgb8,
        )
        .map_err(|source| LaneIoError::WriteImage {
            path: path.display().to_string(),
            source,
        })
    }

    /// Width of the view, px.
    pub fn width_px(&self) -> usize {
        SIZE_PX
    }

    /// Height of the view, px.
    pub fn height_px(&self) -> usize {
        SIZE_PX
    }

    /// View pixel `(column, row)` of a ground point, if inside the view.
    fn to_view(&self, x_m: f64, y_m: f64) -> Option<(usize, usize)> {
        let r = (1.0 - x_m / self.x_max_m) * SIZE_PX as f64;
        let c = (y_m / self.y_half_m + 1.0) * 0.5 * SIZE_PX as f64;
        (r.is_finite() && c.is_finite() && r >= 0.0 && c >= 0.0)
            .then_some((c as usize, r as usize))
            .filter(|&(c, r)| c < SIZE_PX && r < SIZE_PX)
    }

    /// Draw the view of `frame` with the tracker's lanes (`report`) and the ego lane into `rgb`
    /// (resized to `width_px·height_px·3`, RGB, rows from the top).
    pub fn render(
        &self,
        frame: &GreyFrame,
        report: &TrackReport,
        ego: Option<EgoLaneReport>,
        rgb: &mut Vec<u8>,
    ) {
        rgb.resize(SIZE_PX * SIZE_PX * 3, 0);
        for (px, &s) in rgb.chunks_exact_mut(3).zip(&self.source) {
            let c = match frame.data().get(s as usize) {
                Some(&g) if s != u32::MAX => [g, g, g],
                _ => OFF_GROUND_RGB,
            };
            px.copy_from_slice(&c);
        }
        let mut put = |pt: Option<(usize, usize)>, c: [u8; 3]| {
            if let Some((x, y)) = pt {
                let i = 3 * (y * SIZE_PX + x);
                rgb[i..i + 3].copy_from_slice(&c);
            }
        };
        let la = self.camera.config().lookahead;
        for y in [-0.05, 0.0, 0.05].map(|f| f * self.y_half_m) {
            put(self.to_view(la.near_m, y), RANGE_RGB);
            put(self.to_view(la.far_m, y), RANGE_RGB);
        }
        if let Some(e) = ego {
            // Y = y0 + m·X + c·X² (centre line), marks at ∓W/2 across the lane.
            let m = -e.heading_rad.tan();
            let s = (1.0 + m * m).sqrt();
            let y0 = -e.lateral_offset_m * s;
            let c = 0.5 * e.curvature_per_m * s * s * s;
            let half_w = 0.5 * e.lane_width_m * s;
            let n = 4 * SIZE_PX;
            let la = self.camera.config().lookahead;
            for i in 0..=n {
                let x = la.near_m + (la.far_m - la.near_m) * i as f64 / n as f64;
                let yc = y0 + (m + c * x) * x;
                put(self.to_view(x, yc - half_w), MODEL_RGB);
                put(self.to_view(x, yc + half_w), MODEL_RGB);
                if (i / 12) % 2 == 0 {
                    put(self.to_view(x, yc), MODEL_RGB);
                }
            }
        }
        let hom = self.camera.homography();
        let last_row = frame.height().saturating_sub(1) as f64;
        for (k, lane) in report.lanes.iter().enumerate() {
            let [top, bottom] = lane.rows.map(|r| r.clamp(0.0, last_row));
            for row in top.ceil() as usize..=bottom.floor() as usize {
                let Some(u) = lane.col_seen_at_row(row as f64) else {
                    break;
                };
                if let Ok([x, y]) = hom.image_to_ground([u, row as f64]) {
                    put(self.to_view(x, y), LANE_RGB[k]);
                }
            }
        }
        // The camera: a small triangle at the bottom centre.
        for d in 0..4usize {
            for c in SIZE_PX / 2 - d..=SIZE_PX / 2 + d {
                put(Some((c, SIZE_PX - 4 + d)), RANGE_RGB);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_support::{report, tracked_lane};
    use lane_tracker::{LaneReport, LaneState, Side};

    /// A straight mark on the floor at `Y = −0.2 m` is a straight line in the image; the lane
    /// reported along that line is drawn back on `Y = −0.2 m` in the view, over the rows it was
    /// reported on (from the look-ahead's far end to its near end), and a lost lane not at all.
    #[test]
    fn a_lane_along_a_floor_line_is_drawn_back_on_that_line_over_its_rows() {
        let (camera, view) = crate::test_support::robot_view();
        let hom = camera.homography();
        let la = camera.config().lookahead;
        let y_m = -0.2;
        let [u_near, v_near] = hom.ground_to_image([la.near_m, y_m]).unwrap();
        let [u_far, v_far] = hom.ground_to_image([la.far_m, y_m]).unwrap();
        let a2 = (u_far - u_near) / (v_far - v_near);
        let left = tracked_lane(Side::Left, [0.0, a2, u_near - a2 * v_near], [v_far, v_near]);
        let right = LaneReport {
            state: LaneState::Lost,
            coeffs: None,
            ..tracked_lane(Side::Right, [0.0; 3], [0.0; 2])
        };
        let report = report([left, right], None);
        let [w, h] = camera.config().image_size_px;
        let frame = GreyFrame::from_vec(w, h, vec![128; w * h]).unwrap();
        let mut rgb = Vec::new();
        view.render(&frame, &report, None, &mut rgb);
        assert_eq!(rgb.len(), view.width_px() * view.height_px() * 3);
        let coloured = |colour: [u8; 3]| -> Vec<(usize, usize)> {
            rgb.chunks_exact(3)
                .enumerate()
                .filter(|(_, px)| *px == colour)
                .map(|(i, _)| (i % SIZE_PX, i / SIZE_PX))
                .collect()
        };
        let drawn = coloured(LANE_RGB[0]);
        assert!(drawn.len() > 20, "{} pixels drawn", drawn.len());
        let (col, row_far) = view.to_view(la.far_m, y_m).unwrap();
        let (_, row_near) = view.to_view(la.near_m, y_m).unwrap();
        for &(c, _) in &drawn {
            assert!(c.abs_diff(col) <= 1, "column {c}, the line's {col}");
        }
        let rows = drawn.iter().map(|p| p.1);
        let (top, bottom) = (rows.clone().min().unwrap(), rows.max().unwrap());
        assert!(top.abs_diff(row_far) <= 3, "top {top}, far end {row_far}");
        assert!(
            bottom.abs_diff(row_near) <= 3,
            "bottom {bottom}, near end {row_near}"
        );
        assert!(coloured(LANE_RGB[1]).is_empty());
    }
}
