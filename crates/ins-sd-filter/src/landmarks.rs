//! The landmark table: surveyed landmark positions by id.

use ins_errors::earth::Geodetic;
use serde::{Deserialize, Serialize};
use sighting_model::Landmark;

use crate::FilterError;

/// One surveyed landmark (WGS-84), as written in a landmark table file:
///
/// ```toml
/// [[landmarks]]
/// id = 7
/// lat_deg = -23.29
/// lon_deg = -45.80
/// alt_m = 20.0
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LandmarkEntry {
    /// Identifier used by the sightings.
    pub id: u32,
    /// Geodetic latitude, degrees (north positive), within [−90, 90].
    pub lat_deg: f64,
    /// Longitude, degrees (east positive).
    pub lon_deg: f64,
    /// Height above the WGS-84 ellipsoid, m.
    pub alt_m: f64,
}

/// Landmarks by id, sorted for lookup (built once; lookups do not allocate).
#[derive(Clone, Debug, PartialEq)]
pub struct LandmarkTable {
    sorted: Vec<(u32, Landmark)>,
}

impl LandmarkTable {
    /// A table from entries in any order.
    ///
    /// # Errors
    /// [`FilterError::DuplicateLandmark`] for a repeated id; [`FilterError::Sighting`] (t = NaN)
    /// when a coordinate is not finite or the latitude is outside ±90°.
    pub fn new(entries: &[LandmarkEntry]) -> Result<Self, FilterError> {
        let mut sorted = Vec::with_capacity(entries.len());
        for e in entries {
            let lm = Landmark::new(
                e.id as usize,
                Geodetic::from_deg(e.lat_deg, e.lon_deg, e.alt_m),
            )
            .map_err(|source| FilterError::Sighting {
                t_s: f64::NAN,
                landmark: e.id,
                source,
            })?;
            sorted.push((e.id, lm));
        }
        sorted.sort_by_key(|(id, _)| *id);
        for w in sorted.windows(2) {
            if w[0].0 == w[1].0 {
                return Err(FilterError::DuplicateLandmark { id: w[0].0 });
            }
        }
        Ok(Self { sorted })
    }

    /// The landmark with id `id`, if any.
    pub fn get(&self, id: u32) -> Option<&Landmark> {
        self.sorted
            .binary_search_by_key(&id, |(i, _)| *i)
            .ok()
            .map(|k| &self.sorted[k].1)
    }

    /// Number of landmarks.
    pub fn len(&self) -> usize {
        self.sorted.len()
    }

    /// True when the table is empty.
    pub fn is_empty(&self) -> bool {
        self.sorted.is_empty()
    }

    /// (id, landmark) in increasing id order.
    pub fn iter(&self) -> impl Iterator<Item = (u32, &Landmark)> {
        self.sorted.iter().map(|(i, l)| (*i, l))
    }
}
