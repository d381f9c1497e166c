//! Stripe pairing: keep only the edge pixels that bound a **bright stripe** (an addition beyond
//! the paper; see the crate docs, "Stripe pairing").

use crate::edges::EdgeBuffer;

/// Bit of [`crate::EdgePixel::magnitude`] used as a temporary "kept" flag (magnitudes are at
/// most 2040 < 2¹¹).
const KEEP_BIT: u16 = 1 << 15;
/// Bit used as a temporary "rising edge" flag (`gx > 0`).
const RISE_BIT: u16 = 1 << 14;
/// Temporary "side of a dark stripe" flag.
const DARK_BIT: u16 = 1 << 13;
/// Bits of a real magnitude (at most 2040 < 2¹¹).
const MAG_MASK: u16 = (1 << 11) - 1;

/// Keeps, in every row, only the edge pixels that pair with an edge pixel of the **same class**
/// and the **opposite horizontal polarity** within `max_width_px` columns, the rising one
/// (`gx > 0`, dark → bright to the right) on the left and the falling one (`gx < 0`) on the
/// right: the two sides of a bright stripe at most `max_width_px` wide along the row. A dark
/// stripe (the seam beside a mark, a tar joint), the single edge of a dark object (a car, a
/// kerb's shadow, a wall) and a bright area wider than `max_width_px` no longer pass.
///
/// `edges` must come from [`crate::GradientDetector::detect`] (rows stored contiguously,
/// columns increasing within a row; the polarity is the sign of the stored Sobel
/// [`crate::EdgePixel::gx`]). `max_width_px = 0` keeps everything. Returns the number of
/// pixels dropped. A class image painted by `detect` is left as it was (it shows every edge
/// pixel; repaint it from `edges` to show only the stripes). No allocation.
pub fn keep_bright_stripes(
    edges: &mut EdgeBuffer,
    max_width_px: u16,
    outward_steps_from_col_px: Option<u16>,
) -> usize {
    if max_width_px == 0 {
        return 0;
    }
    mark(edges, max_width_px, outward_steps_from_col_px);
    edges.retain_flagged(KEEP_BIT, MAG_MASK)
}

/// Splits `edges` for weighting instead of discarding: the pixels that pair into bright stripes
/// (as in [`keep_bright_stripes`]) are copied into `paired` (cleared first; pixels past its
/// capacity are counted as dropped there), and with `drop_dark_stripes` the pixels that bound
/// only a **dark** stripe at most `max_width_px` wide (falling then rising along the row: the
/// seam beside a mark, a tar joint, a crack) are removed from `edges`; single steps (a kerb, a
/// road edge) stay. Returns the number of paired pixels. `max_width_px = 0` copies and drops
/// nothing. Polarities come from the Sobel `gx` stored with each pixel
/// ([`crate::EdgePixel::gx`]), so `edges` must come from [`crate::GradientDetector::detect`].
/// No allocation.
pub fn split_stripes(
    edges: &mut EdgeBuffer,
    paired: &mut EdgeBuffer,
    max_width_px: u16,
    drop_dark_stripes: bool,
) -> usize {
    paired.clear();
    if max_width_px == 0 {
        return 0;
    }
    mark(edges, max_width_px, None);
    let mut n = 0;
    for p in edges.pixels_mut() {
        if p.magnitude & KEEP_BIT != 0 {
            n += 1;
            let mut q = *p;
            q.magnitude &= MAG_MASK;
            paired.push(q);
        } else if !(drop_dark_stripes && p.magnitude & DARK_BIT != 0) {
            // Kept in `edges`: reuse KEEP_BIT as the retain flag below.
            p.magnitude |= KEEP_BIT;
        }
    }
    // Bright-stripe pixels carry KEEP_BIT already; dark-only ones (when dropped) do not.
    edges.retain_flagged(KEEP_BIT, MAG_MASK);
    n
}

/// Pass 1 of the pairing: the flags cleared, [`RISE_BIT`] set on the rising pixels (from the
/// Sobel `gx` the detector stored with each pixel).
fn flag_polarity(px: &mut [crate::EdgePixel]) {
    for p in px.iter_mut() {
        p.magnitude &= MAG_MASK;
        if p.gx > 0 {
            p.magnitude |= RISE_BIT;
        }
    }
}

/// Sets [`KEEP_BIT`] on the pixels that pair (or are outward steps), [`RISE_BIT`] on the rising
/// ones; magnitudes are restored by the callers.
fn mark(edges: &mut EdgeBuffer, max_width_px: u16, outward_steps_from_col_px: Option<u16>) {
    let w = usize::from(max_width_px);
    let px = edges.pixels_mut();
    flag_polarity(px);
    // Pass 2, per row run, two linear scans (columns increase within a row, so the nearest
    // pixel of a class and polarity after `j` in the run is the nearest to its right, and the
    // nearest before it the nearest to its left). Backwards, with the nearest later column per
    // class and polarity: a rising pixel with a falling partner within `w` to its right bounds
    // a bright stripe, a falling one with a rising pixel there a dark one.
    let n = px.len();
    let mut start = 0;
    while start < n {
        let end = crate::edges::row_end(px, start);
        // Indexed by `EdgeClass as usize` (1, 2).
        let (mut next_rise, mut next_fall) = ([None::<u16>; 3], [None::<u16>; 3]);
        for p in px[start..end].iter_mut().rev() {
            let c = p.class as usize;
            let rising = p.magnitude & RISE_BIT != 0;
            let limit = usize::from(p.col_px) + w;
            let near = |col: Option<u16>| col.is_some_and(|q| usize::from(q) <= limit);
            if rising {
                if near(next_fall[c]) {
                    p.magnitude |= KEEP_BIT;
                }
                next_rise[c] = Some(p.col_px);
            } else {
                if near(next_rise[c]) {
                    p.magnitude |= DARK_BIT;
                }
                next_fall[c] = Some(p.col_px);
            }
        }
        // Forwards, with the nearest earlier column: a falling pixel with a rising partner
        // within `w` to its left bounds a bright stripe, a rising one with a falling pixel
        // there a dark one; and the outward steps.
        let (mut prev_rise, mut prev_fall) = ([None::<u16>; 3], [None::<u16>; 3]);
        for p in &mut px[start..end] {
            let c = p.class as usize;
            let rising = p.magnitude & RISE_BIT != 0;
            let col = usize::from(p.col_px);
            let near = |q: Option<u16>| q.is_some_and(|q| usize::from(q) + w >= col);
            if rising {
                if near(prev_fall[c]) {
                    p.magnitude |= DARK_BIT;
                }
                prev_rise[c] = Some(p.col_px);
            } else {
                if near(prev_rise[c]) {
                    p.magnitude |= KEEP_BIT;
                }
                prev_fall[c] = Some(p.col_px);
            }
            // An unpaired step whose bright side faces away from the column (a kerb, a road
            // edge: the road is the dark side towards the middle).
            if outward_steps_from_col_px
                .is_some_and(|c| (p.col_px > c && rising) || (p.col_px < c && !rising))
            {
                p.magnitude |= KEEP_BIT;
            }
        }
        start = end;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{GradientDetector, GradientParams, GreyImage, Region};

    /// 64×48 image of grey `ground` with a 45° stripe `x + y ∈ [c, c + width)` of grey `mark`.
    fn stripe(ground: u8, mark: u8, c: usize, width: usize) -> Vec<u8> {
        let (w, h) = (64usize, 48usize);
        let mut data = vec![ground; w * h];
        for y in 0..h {
            for x in 0..w {
                if (c..c + width).contains(&(x + y)) {
                    data[y * w + x] = mark;
                }
            }
        }
        data
    }

    /// The pairing rule read literally, pixel by pixel: for each pixel, scan its row to the
    /// right (rising) or left (falling) while within `max_width_px` columns for a pixel of its
    /// class and the opposite polarity (a bright stripe's partner), and the other way for a
    /// dark stripe's. `mark`'s reference.
    fn mark_by_scanning(edges: &mut EdgeBuffer, max_width_px: u16, outward: Option<u16>) {
        let w = usize::from(max_width_px);
        let px = edges.pixels_mut();
        flag_polarity(px);
        let n = px.len();
        for j in 0..n {
            let pj = px[j];
            let rising = pj.magnitude & RISE_BIT != 0;
            let same_row = |q: &crate::EdgePixel| q.row_px == pj.row_px && q.class == pj.class;
            let right = |want_rising: bool| {
                px[j + 1..]
                    .iter()
                    .take_while(|q| q.row_px == pj.row_px)
                    .take_while(|q| usize::from(q.col_px) <= usize::from(pj.col_px) + w)
                    .any(|q| same_row(q) && (q.magnitude & RISE_BIT != 0) == want_rising)
            };
            let left = |want_rising: bool| {
                px[..j]
                    .iter()
                    .rev()
                    .take_while(|q| q.row_px == pj.row_px)
                    .take_while(|q| usize::from(q.col_px) + w >= usize::from(pj.col_px))
                    .any(|q| same_row(q) && (q.magnitude & RISE_BIT != 0) == want_rising)
            };
            let (bright, dark) = if rising {
                (right(false), left(false))
            } else {
                (left(true), right(true))
            };
            let out =
                outward.is_some_and(|c| (pj.col_px > c && rising) || (pj.col_px < c && !rising));
            if bright || out {
                px[j].magnitude |= KEEP_BIT;
            }
            if dark {
                px[j].magnitude |= DARK_BIT;
            }
        }
    }

    /// `mark`'s two linear scans per row flag exactly the pixels the literal scan does, on
    /// seeded random images (noise, stripes of both polarities and widths, steps), for several
    /// widths and with and without outward steps.
    #[test]
    fn the_linear_pairing_scan_flags_what_the_literal_scan_flags() {
        let (w, h) = (96usize, 64usize);
        let det = GradientDetector::new(GradientParams::default()).unwrap();
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        let mut next = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            state
        };
        let mut checked = 0;
        for _ in 0..20 {
            let mut data = vec![0u8; w * h];
            for v in &mut data {
                *v = 60 + (next() % 40) as u8;
            }
            for _ in 0..12 {
                let (x0, width) = ((next() % w as u64) as usize, 1 + (next() % 14) as usize);
                let (lean, level) = ((next() % 5) as f64 * 0.3 - 0.6, (next() % 200) as u8 + 30);
                for y in 0..h {
                    let x = x0 as f64 + lean * y as f64;
                    for dx in 0..width {
                        let c = x as i64 + dx as i64;
                        if (0..w as i64).contains(&c) {
                            data[y * w + c as usize] = level;
                        }
                    }
                }
            }
            let image = GreyImage::new(&data, w, h, w).unwrap();
            let mut edges = EdgeBuffer::with_capacity(w * h);
            det.detect(&image, Region::Full, &mut edges, None).unwrap();
            for (max_width_px, outward) in [(4, None), (12, None), (12, Some(48)), (40, Some(10))] {
                let mut fast = edges.clone();
                let mut literal = edges.clone();
                mark(&mut fast, max_width_px, outward);
                mark_by_scanning(&mut literal, max_width_px, outward);
                assert_eq!(
                    fast.pixels(),
                    literal.pixels(),
                    "width {max_width_px}, {outward:?}"
                );
                checked += fast
                    .pixels()
                    .iter()
                    .filter(|p| p.magnitude & KEEP_BIT != 0)
                    .count();
                checked += fast
                    .pixels()
                    .iter()
                    .filter(|p| p.magnitude & DARK_BIT != 0)
                    .count();
            }
        }
        assert!(
            checked > 1000,
            "too few flagged pixels to compare ({checked})"
        );
    }

    fn run(data: &[u8], max_width_px: u16) -> (usize, usize) {
        let image = GreyImage::new(data, 64, 48, 64).unwrap();
        let det = GradientDetector::new(GradientParams::default()).unwrap();
        let mut edges = EdgeBuffer::with_capacity(4096);
        det.detect(&image, Region::Full, &mut edges, None).unwrap();
        let before = edges.len();
        let dropped = keep_bright_stripes(&mut edges, max_width_px, None);
        assert_eq!(edges.len() + dropped, before);
        assert!(edges.pixels().iter().all(|p| p.magnitude <= 2040));
        (before, edges.len())
    }

    #[test]
    fn a_bright_stripe_keeps_both_edges() {
        let (before, after) = run(&stripe(40, 200, 50, 4), 8);
        assert!(before > 50);
        assert_eq!(before, after);
    }

    #[test]
    fn a_dark_stripe_and_a_single_step_are_dropped() {
        // Dark seam on a bright floor.
        let (before, after) = run(&stripe(200, 40, 50, 4), 8);
        assert!(before > 50);
        assert_eq!(after, 0);
        // A single step (bright half-plane): one polarity only.
        let (before, after) = run(&stripe(40, 200, 50, 200), 8);
        assert!(before > 20);
        assert_eq!(after, 0);
    }

    #[test]
    fn a_stripe_wider_than_the_limit_is_dropped_and_zero_disables() {
        let data = stripe(40, 200, 40, 14);
        assert_eq!(run(&data, 6).1, 0);
        // (The rows where the image border cuts the stripe keep one side only.)
        let (before, after) = run(&data, 20);
        assert!(after * 10 >= before * 9, "{after} of {before}");
        let (before, after) = run(&data, 0);
        assert_eq!(before, after);
    }

    #[test]
    fn splitting_copies_bright_stripes_and_drops_only_dark_ones() {
        let data = stripe(40, 200, 50, 4);
        let image = GreyImage::new(&data, 64, 48, 64).unwrap();
        let det = GradientDetector::new(GradientParams::default()).unwrap();
        let mut edges = EdgeBuffer::with_capacity(4096);
        det.detect(&image, Region::Full, &mut edges, None).unwrap();
        let before = edges.pixels().to_vec();
        let mut paired = EdgeBuffer::with_capacity(4096);
        let n = split_stripes(&mut edges, &mut paired, 8, true);
        assert_eq!(edges.pixels(), &before[..]);
        assert_eq!((n, paired.pixels()), (before.len(), &before[..]));
        // A dark stripe: nothing paired; its sides are dropped only when asked.
        let dark = stripe(200, 40, 50, 4);
        let image = GreyImage::new(&dark, 64, 48, 64).unwrap();
        det.detect(&image, Region::Full, &mut edges, None).unwrap();
        let before = edges.pixels().to_vec();
        assert_eq!(split_stripes(&mut edges, &mut paired, 8, false), 0);
        assert!(paired.is_empty());
        assert_eq!(edges.pixels(), &before[..]);
        assert_eq!(split_stripes(&mut edges, &mut paired, 8, true), 0);
        assert!(edges.is_empty());
        // A single step (a kerb) stays either way.
        let step = stripe(40, 200, 50, 200);
        let image = GreyImage::new(&step, 64, 48, 64).unwrap();
        det.detect(&image, Region::Full, &mut edges, None).unwrap();
        let before = edges.len();
        split_stripes(&mut edges, &mut paired, 8, true);
        assert!(paired.is_empty());
        assert_eq!(edges.len(), before);
    }
}
