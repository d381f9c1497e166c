//! Joint choice of the ego-lane pair among candidate lines (an addition beyond the paper, which
//! takes the best Hough line of each lane class on its own).

use serde::{Deserialize, Serialize};

use crate::HoughError;

/// A lane candidate seen as its chord over the region of interest: its column at the top ROI row
/// and at the bottom ROI row, pixels, and its support (e.g. Hough votes, ≥ 0).
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct Chord {
    /// Column at the top ROI row, pixels.
    pub col_top_px: f64,
    /// Column at the bottom ROI row, pixels.
    pub col_bottom_px: f64,
    /// Support (votes or pixels), ≥ 0; only ratios between candidates matter.
    pub support: f64,
}

/// Geometry of a plausible ego lane seen by a forward camera inside it. Widths are fractions of
/// the image width (so they hold at any resolution).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct EgoPairParams {
    /// Narrowest lane at the bottom ROI row, fraction of the image width, in `[0, max)`.
    /// Default `0.2`.
    pub min_width_frac: f64,
    /// Widest lane at the bottom ROI row, fraction of the image width. Default `1.5`.
    pub max_width_frac: f64,
    /// The left boundary's bottom column may lie at most this far right of the image centre, and
    /// the right boundary's at most this far left of it (the camera is inside the lane), fraction
    /// of the image width, `≥ 0`. Default `0.1`.
    pub centre_margin_frac: f64,
    /// Largest ratio of the lane's width at the top ROI row to its width at the bottom row, in
    /// `[0, 1]`: the boundaries converge towards a vanishing point above the ROI. Default `0.9`.
    pub max_top_width_ratio: f64,
    /// Weight of the pair's offset from the image centre against its support: the score is
    /// `(s_L + s_R)/s_max − centre_weight·|mid − W/2|/W`, `mid` the pair's bottom midpoint,
    /// `s_max` the largest support, `≥ 0`. Default `2.0`.
    pub centre_weight: f64,
    /// A candidate with support below this fraction of the largest is not considered, in
    /// `[0, 1]`. Default `0.2`.
    pub min_support_frac: f64,
    /// Weight of the pair's width at the bottom ROI row against its support, `≥ 0`: the score
    /// loses `width_weight·w_b/W`. With the centre term it makes the boundaries nearest the
    /// image centre on each side win over a wider pair of stronger lines (the ego lane's
    /// boundaries are the nearest marks on each side of the camera). Default `0.0`.
    pub width_weight: f64,
    /// Without a plausible pair, a candidate is reported alone only if its chord leans at least
    /// this many degrees from the vertical over the ROI rows, in `[0, 90)`; `0` = any lean.
    /// One still gives no ground plane: a vertical line alone (a door frame, a pole, a wall's
    /// corner) is as likely a vertical structure as a mark straight ahead, while a mark straight
    /// ahead is still found with its partner. Default `0.0`.
    pub lone_min_lean_deg: f64,
    /// The boundaries may meet within this top fraction of the chord's rows, in `[0, 0.5)`:
    /// the vanishing point lies inside the region of interest when its top rows reach above
    /// the horizon (a camera pitched up, a region set for another camera). Below that row the
    /// pair must be in order. `0`: they meet above the region. Default `0.0`.
    pub meet_top_frac: f64,
}

impl Default for EgoPairParams {
    fn default() -> Self {
        Self {
            min_width_frac: 0.2,
            max_width_frac: 1.5,
            centre_margin_frac: 0.1,
            max_top_width_ratio: 0.9,
            centre_weight: 2.0,
            min_support_frac: 0.2,
            width_weight: 0.0,
            lone_min_lean_deg: 0.0,
            meet_top_frac: 0.0,
        }
    }
}

impl EgoPairParams {
    /// Check every field against its documented range.
    ///
    /// # Errors
    /// [`HoughError::InvalidParam`] naming the first offending field.
    pub fn validate(&self) -> Result<(), HoughError> {
        let bad = |field, value, reason| {
            Err(HoughError::InvalidParam {
                field,
                value,
                reason,
            })
        };
        let fin = |v: f64| v.is_finite();
        if !(fin(self.min_width_frac) && self.min_width_frac >= 0.0) {
            return bad(
                "min_width_frac",
                self.min_width_frac,
                "must be finite and >= 0",
            );
        }
        if !(fin(self.max_width_frac) && self.max_width_frac > self.min_width_frac) {
            return bad(
                "max_width_frac",
                self.max_width_frac,
                "must be finite and > min_width_frac",
            );
        }
        if !(fin(self.centre_margin_frac) && self.centre_margin_frac >= 0.0) {
            return bad(
                "centre_margin_frac",
                self.centre_margin_frac,
                "must be finite and >= 0",
            );
        }
        if !(0.0..=1.0).contains(&self.max_top_width_ratio) {
            return bad(
                "max_top_width_ratio",
                self.max_top_width_ratio,
                "must be in [0, 1]",
            );
        }
        if !(fin(self.centre_weight) && self.centre_weight >= 0.0) {
            return bad(
                "centre_weight",
                self.centre_weight,
                "must be finite and >= 0",
            );
        }
        if !(fin(self.width_weight) && self.width_weight >= 0.0) {
            return bad("width_weight", self.width_weight, "must be finite and >= 0");
        }
        if !(0.0..=1.0).contains(&self.min_support_frac) {
            return bad(
                "min_support_frac",
                self.min_support_frac,
                "must be in [0, 1]",
            );
        }
        if !(0.0..90.0).contains(&self.lone_min_lean_deg) {
            return bad(
                "lone_min_lean_deg",
                self.lone_min_lean_deg,
                "must be in [0, 90)",
            );
        }
        if !(0.0..0.5).contains(&self.meet_top_frac) {
            return bad("meet_top_frac", self.meet_top_frac, "must be in [0, 0.5)");
        }
        Ok(())
    }
}

/// The chosen ego boundaries: indices into the candidate slice.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct EgoChoice {
    /// Left boundary.
    pub left: Option<usize>,
    /// Right boundary.
    pub right: Option<usize>,
}

/// Whether `(left, right)` has the shape of an ego lane, the first two rules of
/// [`choose_ego_pair`]: with `w_b = right.bottom − left.bottom` and `w_t = right.top −
/// left.top`, `w_b ∈ [min_width_frac, max_width_frac]·W`, `w_t ≤ max_top_width_ratio·w_b` and
/// `w_t + meet_top_frac·(w_b − w_t) ≥ 0` (converging upwards, meeting above the region or
/// within its top fraction of rows). The camera-inside rule is not part of it (a tracked pair
/// may leave it in a lane change). Non-finite columns are not plausible.
pub fn pair_shape_is_plausible(
    left: &Chord,
    right: &Chord,
    image_width_px: f64,
    params: &EgoPairParams,
) -> bool {
    let w = image_width_px;
    let wb = right.col_bottom_px - left.col_bottom_px;
    let wt = right.col_top_px - left.col_top_px;
    // `false` for NaN: every comparison with it is.
    wb >= params.min_width_frac * w
        && wb <= params.max_width_frac * w
        && wt + params.meet_top_frac * (wb - wt) >= 0.0
        && wt <= params.max_top_width_ratio * wb
}

/// Chooses the ego lane's two boundaries jointly among `chords` (any lean: on a curve both
/// boundaries can lean the same way). A pair `(L, R)` is plausible when
///
/// * `w_b = R.bottom − L.bottom` lies in `[min_width_frac, max_width_frac]·W`;
/// * the boundaries converge upwards, `w_t = R.top − L.top ≤ max_top_width_ratio·w_b`, and
///   meet above the ROI or within its top `f = meet_top_frac` of the rows: the chords are in
///   order at that row, `w_t + f·(w_b − w_t) ≥ 0` (`w_t ≥ 0` for `f = 0`);
/// * the camera is inside the lane: `L.bottom ≤ W/2 + m` and `R.bottom ≥ W/2 − m`,
///   `m = centre_margin_frac·W`;
///
/// and the plausible pair with the highest
/// `(s_L + s_R)/s_max − centre_weight·|mid − W/2|/W − width_weight·w_b/W` wins (support, and
/// nearness to the image centre: the ego lane, not a neighbour; the width term prefers the
/// nearest boundary on each side over a wider pair). With
/// `locked = Some(i)`, only pairs containing chord `i` are considered (a boundary already
/// tracked). Without a plausible pair, the single candidate with the best
/// `s/s_max − centre_weight·|bottom − W/2|/W` among those whose lean from the vertical,
/// `atan(|top − bottom| / chord_rows_px)`, is at least `lone_min_lean_deg` is returned on the
/// side of the centre its bottom lies (or `locked` alone). `chord_rows_px` is the number of rows
/// between a chord's top and bottom rows (`> 0`). Candidates with non-finite columns or support
/// below `min_support_frac·s_max` are skipped. No allocation.
pub fn choose_ego_pair(
    chords: &[Chord],
    image_width_px: f64,
    chord_rows_px: f64,
    params: &EgoPairParams,
    locked: Option<usize>,
) -> EgoChoice {
    let w = image_width_px;
    let c = 0.5 * w;
    let s_max = chords
        .iter()
        .map(|ch| ch.support)
        .filter(|s| s.is_finite())
        .fold(0.0f64, f64::max);
    if !(s_max > 0.0 && w > 0.0) {
        return EgoChoice::default();
    }
    let usable = |i: usize| {
        let ch = &chords[i];
        ch.col_top_px.is_finite()
            && ch.col_bottom_px.is_finite()
            && ch.support.is_finite()
            && (ch.support >= params.min_support_frac * s_max || locked == Some(i))
    };
    let m = params.centre_margin_frac * w;
    let mut best: Option<(f64, usize, usize)> = None;
    for l in 0..chords.len() {
        for r in 0..chords.len() {
            if l == r || !usable(l) || !usable(r) {
                continue;
            }
            if locked.is_some_and(|k| k != l && k != r) {
                continue;
            }
            let (cl, cr) = (&chords[l], &chords[r]);
            let wb = cr.col_bottom_px - cl.col_bottom_px;
            let ok = pair_shape_is_plausible(cl, cr, w, params)
                && cl.col_bottom_px <= c + m
                && cr.col_bottom_px >= c - m;
            if !ok {
                continue;
            }
            let mid = 0.5 * (cl.col_bottom_px + cr.col_bottom_px);
            let score = (cl.support + cr.support) / s_max
                - params.centre_weight * (mid - c).abs() / w
                - params.width_weight * wb / w;
            if best.is_none_or(|(b, _, _)| score > b) {
                best = Some((score, l, r));
            }
        }
    }
    if let Some((_, l, r)) = best {
        return EgoChoice {
            left: Some(l),
            right: Some(r),
        };
    }
    // tan of the least lean a lone candidate needs (0 when the rule is off).
    let min_lean = params.lone_min_lean_deg.to_radians().tan();
    let leans = |i: usize| {
        let ch = &chords[i];
        (ch.col_top_px - ch.col_bottom_px).abs() >= min_lean * chord_rows_px
    };
    let single = match locked {
        Some(k) if k < chords.len() => Some(k),
        Some(_) => None,
        None => (0..chords.len())
            .filter(|&i| usable(i) && leans(i))
            .map(|i| {
                let ch = &chords[i];
                let s =
                    ch.support / s_max - params.centre_weight * (ch.col_bottom_px - c).abs() / w;
                (s, i)
            })
            .max_by(|a, b| a.0.total_cmp(&b.0))
            .map(|(_, i)| i),
    };
    match single {
        Some(i) if chords[i].col_bottom_px < c => EgoChoice {
            left: Some(i),
            right: None,
        },
        Some(i) => EgoChoice {
            left: None,
            right: Some(i),
        },
        None => EgoChoice::default(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ch(top: f64, bottom: f64, support: f64) -> Chord {
        Chord {
            col_top_px: top,
            col_bottom_px: bottom,
            support,
        }
    }

    #[test]
    fn the_inner_pair_wins_over_a_stronger_neighbour_lane() {
        // 320 px wide. Ego boundaries at 60 and 260 (bottom), converging to 140/180 at the top;
        // a neighbour lane's boundary at −140 (bottom) with more support.
        let chords = [
            ch(100.0, -140.0, 100.0),
            ch(140.0, 60.0, 60.0),
            ch(180.0, 260.0, 80.0),
        ];
        let p = EgoPairParams::default();
        let got = choose_ego_pair(&chords, 320.0, 100.0, &p, None);
        assert_eq!(
            got,
            EgoChoice {
                left: Some(1),
                right: Some(2)
            }
        );
    }

    #[test]
    fn boundaries_leaning_the_same_way_on_a_curve_form_a_pair() {
        // Both lean `\` (top left of bottom), converging upwards.
        let chords = [ch(20.0, 100.0, 50.0), ch(120.0, 300.0, 50.0)];
        let got = choose_ego_pair(&chords, 320.0, 100.0, &EgoPairParams::default(), None);
        assert_eq!(
            got,
            EgoChoice {
                left: Some(0),
                right: Some(1)
            }
        );
    }

    #[test]
    fn boundaries_may_meet_within_the_top_fraction_and_nowhere_lower() {
        // 100 chord rows; ego boundaries 200 px apart at the bottom that cross 10 rows below
        // the top (the vanishing point inside the region): 22.2 px crossed at the top.
        let (l_bottom, r_bottom, meet_row) = (60.0, 260.0, 10.0);
        let top = |bottom: f64| 160.0 + (bottom - 160.0) * (-meet_row) / (100.0 - meet_row);
        let chords = [
            ch(top(l_bottom), l_bottom, 50.0),
            ch(top(r_bottom), r_bottom, 50.0),
        ];
        assert!(
            chords[0].col_top_px > chords[1].col_top_px,
            "crossed at the top"
        );
        let pair = EgoChoice {
            left: Some(0),
            right: Some(1),
        };
        let with = |f: f64| EgoPairParams {
            meet_top_frac: f,
            ..EgoPairParams::default()
        };
        // They meet at 0.1 of the rows: a pair for f above it, not below.
        for (f, is_pair) in [(0.0, false), (0.09, false), (0.11, true), (0.25, true)] {
            let got = choose_ego_pair(&chords, 320.0, 100.0, &with(f), None);
            assert_eq!(got == pair, is_pair, "meet_top_frac {f}: {got:?}");
        }
        assert!(with(0.5).validate().is_err() && with(-0.1).validate().is_err());
        assert!(with(0.49).validate().is_ok());
    }

    #[test]
    fn a_pairs_shape_is_its_width_and_its_convergence_not_where_the_camera_is() {
        let p = EgoPairParams::default(); // width 0.2–1.5 W, top ≤ 0.9 × bottom
        let shape = |l: (f64, f64), r: (f64, f64)| {
            pair_shape_is_plausible(&ch(l.0, l.1, 1.0), &ch(r.0, r.1, 1.0), 320.0, &p)
        };
        // (top, bottom) columns; bottom width 200 px.
        assert!(shape((120.0, 60.0), (200.0, 260.0)), "converging");
        assert!(
            shape((70.0, 60.0), (250.0, 260.0)),
            "top 0.9 × bottom: at the bound"
        );
        assert!(!shape((69.0, 60.0), (251.0, 260.0)), "top 0.91 × bottom");
        assert!(!shape((40.0, 60.0), (280.0, 260.0)), "diverging upwards");
        assert!(
            !shape((150.0, 140.0), (170.0, 180.0)),
            "40 px: narrower than 0.2 W"
        );
        assert!(
            !shape((0.0, -300.0), (400.0, 300.0)),
            "600 px: wider than 1.5 W"
        );
        // Both boundaries right of the centre and its margin (a lane change): still an ego
        // lane's shape, which the choice refuses (the camera is not inside it).
        assert!(shape((230.0, 200.0), (270.0, 330.0)));
        let got = choose_ego_pair(
            &[ch(230.0, 200.0, 1.0), ch(270.0, 330.0, 1.0)],
            320.0,
            100.0,
            &p,
            None,
        );
        assert_ne!(
            (got.left, got.right),
            (Some(0), Some(1)),
            "the choice keeps the camera inside"
        );
        assert!(!shape((f64::NAN, 60.0), (200.0, 260.0)), "not a number");
    }

    #[test]
    fn implausible_pairs_are_refused() {
        let p = EgoPairParams::default();
        // Crossing inside the ROI (wider at the top than at the bottom, crossed).
        let crossed = [ch(250.0, 60.0, 50.0), ch(70.0, 260.0, 50.0)];
        let got = choose_ego_pair(&crossed, 320.0, 100.0, &p, None);
        assert!(got.left.is_none() || got.right.is_none());
        // Too narrow: two edges of one mark.
        let narrow = [ch(150.0, 100.0, 50.0), ch(152.0, 108.0, 50.0)];
        let got = choose_ego_pair(&narrow, 320.0, 100.0, &p, None);
        assert!(got.left.is_none() || got.right.is_none());
        // Both right of the centre: no pair; the single best is reported on its side.
        let right_only = [ch(200.0, 250.0, 50.0), ch(230.0, 400.0, 40.0)];
        let got = choose_ego_pair(&right_only, 320.0, 100.0, &p, None);
        assert_eq!(
            got,
            EgoChoice {
                left: None,
                right: Some(0)
            }
        );
    }

    #[test]
    fn a_vertical_line_is_reported_in_a_pair_but_not_alone() {
        let pick = |left, right| EgoChoice { left, right };
        // 320 px wide, chords over 100 rows (unless stated). A door frame: vertical at 176.
        let door = [ch(176.0, 176.0, 100.0)];
        let lean = EgoPairParams {
            lone_min_lean_deg: 5.0,
            ..EgoPairParams::default()
        };
        let any = EgoPairParams {
            lone_min_lean_deg: 0.0,
            ..lean
        };
        // 6 px over 100 rows leans 3.4°: too steep alone, and a weaker line leaning 10° is
        // reported instead; over 50 rows the same 6 px lean 6.8° and the stronger line wins.
        let two = [ch(170.0, 176.0, 100.0), ch(182.6, 200.0, 40.0)];
        // A mark straight ahead (vertical, left of the centre) with its partner.
        let pair = [ch(130.0, 130.0, 100.0), ch(200.0, 300.0, 80.0)];
        // (chords, rows of a chord, parameters, locked chord, the choice wanted)
        type Case<'a> = (
            &'a [Chord],
            f64,
            &'a EgoPairParams,
            Option<usize>,
            EgoChoice,
        );
        let cases: [Case; 6] = [
            (&door, 100.0, &lean, None, pick(None, None)),
            (&door, 100.0, &any, None, pick(None, Some(0))),
            (&two, 100.0, &lean, None, pick(None, Some(1))),
            (&two, 50.0, &lean, None, pick(None, Some(0))),
            (&pair, 100.0, &lean, None, pick(Some(0), Some(1))),
            // A tracked (locked) vertical lane stays, alone too.
            (&door, 100.0, &lean, Some(0), pick(None, Some(0))),
        ];
        for (k, (chords, rows, params, locked, want)) in cases.into_iter().enumerate() {
            let got = choose_ego_pair(chords, 320.0, rows, params, locked);
            assert_eq!(got, want, "case {k}");
        }
        for bad in [-1.0, 90.0, f64::NAN] {
            let p = EgoPairParams {
                lone_min_lean_deg: bad,
                ..lean
            };
            assert!(p.validate().is_err(), "{bad}");
        }
    }

    #[test]
    fn a_locked_boundary_is_kept_and_weak_or_bad_candidates_are_skipped() {
        let p = EgoPairParams::default();
        let chords = [
            ch(140.0, 60.0, 10.0),      // locked (tracked), weak
            ch(180.0, 260.0, 100.0),    // right partner
            ch(f64::NAN, 200.0, 500.0), // bad
            ch(185.0, 250.0, 5.0),      // below min_support_frac
        ];
        let got = choose_ego_pair(&chords, 320.0, 100.0, &p, Some(0));
        assert_eq!(
            got,
            EgoChoice {
                left: Some(0),
                right: Some(1)
            }
        );
        assert_eq!(
            choose_ego_pair(&[], 320.0, 100.0, &p, None),
            EgoChoice::default()
        );
        assert!(p.validate().is_ok());
        let bad = EgoPairParams {
            max_top_width_ratio: 1.5,
            ..p
        };
        assert!(bad.validate().is_err());
    }
}
