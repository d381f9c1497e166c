//! Stage I, the directional gradient (paper eqs. 1–3, crate `vision-gradient`): over the whole
//! region searched when a lane is (re-)initialised, inside one lane's windows on a tracked frame.
//! Over a region the periodic stripes of a crosswalk are dropped
//! (`gradient.periodic_min_stripes`) and the bright stripes' sides either kept alone or split off
//! to vote more (`gradient.stripe_paired_votes`).
//!
//! Decisions and figures: `docs/lanes/history/stripe-pairing-and-ego-pair.md`,
//! `periodic-stripes.md`.

use vision_gradient::{
    ColSpan, EdgeBuffer, GradientDetector, GreyImage, Region, drop_periodic_stripes,
    keep_bright_stripes, split_stripes,
};

use super::setup::{Rows, Setup};
use crate::TrackerError;

/// The gradient stage: the detector and its two output buffers.
#[derive(Debug)]
pub(super) struct EdgeStage {
    detector: GradientDetector,
    /// The last detection's edge pixels (after the stripe filters).
    pub(super) edges: EdgeBuffer,
    /// The edge pixels that pair into bright stripes (`gradient.stripe_paired_votes > 0`), split
    /// off `edges` by the last detection over a region.
    pub(super) paired: EdgeBuffer,
}

impl EdgeStage {
    /// The detector of `setup.cfg.gradient`, its buffers holding `capacity` pixels (the tallest
    /// region searched).
    pub(super) fn new(setup: &Setup, capacity: usize) -> Result<Self, TrackerError> {
        Ok(EdgeStage {
            detector: GradientDetector::new(setup.cfg.gradient.params())?,
            edges: EdgeBuffer::with_capacity(capacity),
            paired: EdgeBuffer::with_capacity(capacity),
        })
    }

    /// The edges of the rows `rows` of `image` (an initialisation's search): the detector, the
    /// periodic stripes dropped, then the bright stripes' sides split into `paired`
    /// (`gradient.stripe_paired_votes > 0`) or kept alone.
    pub(super) fn detect_rows(
        &mut self,
        image: &GreyImage<'_>,
        rows: Rows,
        setup: &Setup,
    ) -> Result<(), TrackerError> {
        let (top, bottom) = rows;
        let g = &setup.cfg.gradient;
        self.detector.detect(
            image,
            Region::Rows {
                row_start_px: top,
                row_end_px: bottom,
            },
            &mut self.edges,
            None,
        )?;
        drop_periodic_stripes(&mut self.edges, &g.periodic_params());
        if g.stripe_paired_votes > 0 {
            split_stripes(
                &mut self.edges,
                &mut self.paired,
                g.stripe_max_width_px,
                g.stripe_drop_dark,
            );
        } else {
            keep_bright_stripes(&mut self.edges, g.stripe_max_width_px, setup.outward_col());
        }
        Ok(())
    }

    /// The edges inside one lane's windows `spans` (a tracked frame or a refinement pass).
    /// Stripe pairing that drops unpaired pixels (`gradient.stripe_paired_votes = 0`) applies
    /// in the windows too; with weighted pairing the windows keep every pixel.
    pub(super) fn detect_windows(
        &mut self,
        image: &GreyImage<'_>,
        spans: &[ColSpan],
        setup: &Setup,
    ) -> Result<(), TrackerError> {
        self.detector
            .detect(image, Region::Spans(spans), &mut self.edges, None)?;
        let g = &setup.cfg.gradient;
        let stripe_px = if g.stripe_paired_votes > 0 {
            0
        } else {
            g.stripe_max_width_px
        };
        keep_bright_stripes(&mut self.edges, stripe_px, setup.outward_col());
        Ok(())
    }
}
