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

/// Sets [`KEEP_BIT`] on the pixels that pair (or are outward steps), [`RISE_BIT`] on the rising
/// ones; magnitudes are restored by the callers.
fn mark(edges: &mut EdgeBuffer, max_width_px: u16, outward_steps_from_col_px: Option<u16>) {
    let w = usize::from(max_width_px);
    let px = edges.pixels_mut();
    // Pass 1: polarity flags, from the Sobel gx the detector stored with each pixel.
    for p in px.iter_mut() {
        p.magnitude &= MAG_MASK;
        if p.gx > 0 {
            p.magnitude |= RISE_BIT;
        }
    }
    // Pass 2: per row run, mark the pixels that have a partner.
    let n = px.len();
    let mut start = 0;
    while start < n {
        let row = px[start].row_px;
        let mut end = start + 1;
        while end < n && px[end].row_px == row {
            end += 1;
        }
        for j in start..end {
            let pj = px[j];
            let rising = pj.magnitude & RISE_BIT != 0;
            let partner = if rising {
                px[j + 1..end]
                    .iter()
                    .take_while(|q| usize::from(q.col_px) <= usize::from(pj.col_px) + w)
                    .any(|q| q.class == pj.class && q.magnitude & RISE_BIT == 0)
            } else {
                px[start..j]
                    .iter()
                    .rev()
                    .take_while(|q| usize::from(q.col_px) + w >= usize::from(pj.col_px))
                    .any(|q| q.class == pj.class && q.magnitude & RISE_BIT != 0)
            };
            // An unpaired step whose bright side faces away from the column (a kerb, a road
            // edge: the road is the dark side towards the middle).
            let outward = outward_steps_from_col_px
                .is_some_and(|c| (pj.col_px > c && rising) || (pj.col_px < c && !rising));
            if partner || outward {
                px[j].magnitude |= KEEP_BIT;
            }
            // The sides of a dark stripe: falling with a rising partner on its right, rising
            // with a falling partner on its left.
            let dark = if rising {
                px[start..j]
                    .iter()
                    .rev()
                    .take_while(|q| usize::from(q.col_px) + w >= usize::from(pj.col_px))
                    .any(|q| q.class == pj.class && q.magnitude & RISE_BIT == 0)
            } else {
                px[j + 1..end]
                    .iter()
                    .take_while(|q| usize::from(q.col_px) <= usize::from(pj.col_px) + w)
                    .any(|q| q.class == pj.class && q.magnitude & RISE_BIT != 0)
            };
            if dark {
                px[j].magnitude |= DARK_BIT;
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
