//! What a mesh run asks of the decimator, as plain values: `tinsmith mesh`'s flags (through
//! `tinsmith_pipeline::MeshJob`) and the Python binding's `tinsmith.mesh` arguments both
//! fill in one [`DecimationChoices`], and both turn it into the core's
//! [`DecimationOptions`] through [`DecimationChoices::decimation_options`], so the two
//! cannot drift apart. No I/O and no GDAL.

use tinsmith_core::{
    DecimationOptions, EdgeSelection, ErrorModel, InitialMesh, Order, Retriangulation,
    VertexHeights,
};

/// Why [`DecimationChoices::decimation_options`] refused the choices.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ChoiceError {
    /// Neither an error bound nor a count target was given.
    #[error("give a maximum error, or a count target (a maximum triangle or vertex count)")]
    NoTarget,
    /// Flips or extended removals were asked for with a count target.
    #[error(
        "flip rounds and extend rounds work to an error bound, not with a maximum triangle \
         or vertex count"
    )]
    RoundsWithCount,
    /// The contour levels are unusable.
    #[error(transparent)]
    Contour(#[from] tinsmith_contour::Error),
}

/// The decimation a mesh run asks for: the target (an error bound, a count, or both), how
/// removals are chosen and holes filled, and the contour levels the TIN is shaped for.
/// [`DecimationChoices::default`] gives the defaults `tinsmith mesh --help` shows.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct DecimationChoices {
    /// Largest allowed |sample - TIN| at any valid sample; `None` with a count target.
    pub max_error: Option<f64>,
    /// Decimate until at most this many triangles remain (greedy order).
    pub max_triangles: Option<usize>,
    /// Decimate until at most this many vertices remain (greedy order).
    pub max_vertices: Option<usize>,
    /// How a candidate triangle's error is measured.
    pub error_model: ErrorModel,
    /// Edge selection when holes are retriangulated by ears.
    pub selection: EdgeSelection,
    /// Removal order (a count target always removes greedily).
    pub order: Order,
    /// Hole retriangulation.
    pub retriangulate: Retriangulation,
    /// Largest hole solved optimally by dynamic programming.
    pub dp_max_ring: u16,
    /// The mesh decimation starts from.
    pub initial_mesh: InitialMesh,
    /// Longest triangle edge allowed, in sample spacings.
    pub max_edge_length: Option<u32>,
    /// Rounds of error-lowering edge flips after decimating.
    pub flip_rounds: usize,
    /// Rounds of extended-hole removals after decimating.
    pub extend_rounds: usize,
    /// Where vertices sit in height.
    pub vertex_heights: VertexHeights,
    /// Shape the TIN for contour lines every this much (plus `contour_offset`).
    pub contour_interval: Option<f64>,
    /// Shift of the `contour_interval` levels.
    pub contour_offset: Option<f64>,
    /// Shape the TIN for contour lines at these levels (used without `contour_interval`).
    pub contour_levels: Vec<f64>,
}

impl Default for DecimationChoices {
    fn default() -> DecimationChoices {
        DecimationChoices {
            max_error: None,
            max_triangles: None,
            max_vertices: None,
            error_model: ErrorModel::default(),
            selection: EdgeSelection::default(),
            order: Order::default(),
            retriangulate: Retriangulation::default(),
            dp_max_ring: 8,
            initial_mesh: InitialMesh::default(),
            max_edge_length: None,
            flip_rounds: 0,
            extend_rounds: 0,
            vertex_heights: VertexHeights::default(),
            contour_interval: None,
            contour_offset: None,
            contour_levels: Vec::new(),
        }
    }
}

impl DecimationChoices {
    /// Whether a triangle or vertex count is the target.
    pub fn has_count_target(&self) -> bool {
        self.max_triangles.is_some() || self.max_vertices.is_some()
    }

    /// The removal order a run uses: greedy with a count target, else [`Self::order`].
    pub fn effective_order(&self) -> Order {
        match self.has_count_target() {
            true => Order::Greedy,
            false => self.order,
        }
    }

    /// The decimation options asked for, with `bound` as the bound (the asked
    /// `max_error`, or less where an output format rounds heights); contour levels from
    /// `contour_interval` run over `heights`, the valid range of the samples (none
    /// without valid samples).
    ///
    /// # Errors
    /// [`ChoiceError::NoTarget`] without `max_error` and without a count;
    /// [`ChoiceError::RoundsWithCount`] when flips or extended removals come with a
    /// count; [`ChoiceError::Contour`] for an unusable interval or level.
    pub fn decimation_options(
        &self,
        bound: f64,
        heights: Option<(f64, f64)>,
    ) -> Result<DecimationOptions, ChoiceError> {
        if self.max_error.is_none() && !self.has_count_target() {
            return Err(ChoiceError::NoTarget);
        }
        if self.has_count_target() && (self.flip_rounds > 0 || self.extend_rounds > 0) {
            return Err(ChoiceError::RoundsWithCount);
        }
        let mut options = DecimationOptions::new(bound)
            .with_selection(self.selection)
            .with_error_model(self.error_model)
            .with_order(self.order)
            .with_retriangulation(self.retriangulate)
            .with_initial_mesh(self.initial_mesh);
        options.dp_max_ring = self.dp_max_ring as usize;
        options.max_edge_length = self.max_edge_length;
        options.flip_rounds = self.flip_rounds;
        options.extend_rounds = self.extend_rounds;
        options.vertex_heights = self.vertex_heights;
        if let Some(n) = self.max_triangles {
            options = options.with_max_triangles(n);
        }
        if let Some(n) = self.max_vertices {
            options = options.with_max_vertices(n);
        }
        if let Some(levels) = self.contour_levels_over(heights)? {
            options = options.with_contour_levels(&levels);
        }
        Ok(options)
    }

    /// The contour levels the TIN is shaped for over samples whose valid range is
    /// `heights`: every `contour_interval` (none without valid samples), else the sorted
    /// `contour_levels`; `None` when neither is asked.
    fn contour_levels_over(
        &self,
        heights: Option<(f64, f64)>,
    ) -> Result<Option<Vec<f64>>, tinsmith_contour::Error> {
        Ok(match (self.contour_interval, heights) {
            (Some(interval), Some((lo, hi))) => {
                let offset = self.contour_offset.unwrap_or(0.0);
                Some(tinsmith_contour::interval_levels(interval, offset, lo, hi)?)
            }
            (Some(_), None) => Some(Vec::new()),
            (None, _) if !self.contour_levels.is_empty() => {
                Some(tinsmith_contour::sorted_levels(&self.contour_levels)?)
            }
            (None, _) => None,
        })
    }

    /// The triangles of the start mesh a count target decimates from, on `samples`
    /// samples: four times the triangles asked for (a vertex count asks for twice as many
    /// triangles), at most the full grid's two per sample; 0 without a count target.
    /// Memory estimates charge each of these triangles.
    pub fn count_target_start_triangles(&self, samples: u64) -> u64 {
        if !self.has_count_target() {
            return 0;
        }
        let by_vertices = self
            .max_vertices
            .map_or(u64::MAX, |v| (v as u64).saturating_mul(2));
        let target = self
            .max_triangles
            .map_or(u64::MAX, |t| t as u64)
            .min(by_vertices);
        target.saturating_mul(4).min(samples.saturating_mul(2))
    }

    /// Whether decimation raises the vertex heights for these choices on samples whose
    /// valid heights span `heights` (the core's rule,
    /// [`DecimationOptions::raises_vertex_heights`], on the options asked for with the
    /// asked bound).
    pub fn raises_vertex_heights(&self, heights: Option<(f64, f64)>) -> bool {
        let max_abs = heights.map_or(0.0, |(lo, hi)| lo.abs().max(hi.abs()));
        let bound = self.max_error.unwrap_or(f64::INFINITY);
        self.decimation_options(bound, heights)
            .is_ok_and(|options| options.raises_vertex_heights(max_abs))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_target_is_required_and_rounds_need_a_bound() {
        let mut choices = DecimationChoices::default();
        let refused = choices.decimation_options(1.0, None).unwrap_err();
        assert!(matches!(refused, ChoiceError::NoTarget), "{refused}");
        choices.max_triangles = Some(10);
        choices.flip_rounds = 1;
        let refused = choices.decimation_options(1.0, None).unwrap_err();
        assert!(matches!(refused, ChoiceError::RoundsWithCount), "{refused}");
        assert_eq!(choices.effective_order(), Order::Greedy);
        assert_eq!(choices.count_target_start_triangles(1000), 40);
        assert_eq!(choices.count_target_start_triangles(10), 20);
        choices.max_vertices = Some(3);
        assert_eq!(choices.count_target_start_triangles(1000), 24);
        assert_eq!(
            DecimationChoices::default().count_target_start_triangles(9),
            0
        );
    }

    #[test]
    fn every_choice_reaches_the_options() {
        let choices = DecimationChoices {
            max_error: Some(2.0),
            error_model: ErrorModel::Bounds,
            retriangulate: Retriangulation::Ears,
            dp_max_ring: 5,
            max_edge_length: Some(7),
            flip_rounds: 2,
            contour_interval: Some(10.0),
            contour_offset: Some(5.0),
            ..DecimationChoices::default()
        };
        let options = choices.decimation_options(1.5, Some((12.0, 41.0))).unwrap();
        assert_eq!(options.max_error, 1.5);
        assert_eq!(options.error_model, ErrorModel::Bounds);
        assert_eq!(options.retriangulation, Retriangulation::Ears);
        assert_eq!(options.dp_max_ring, 5);
        assert_eq!(options.max_edge_length, Some(7));
        assert_eq!(options.flip_rounds, 2);
        assert_eq!(
            options.contour_levels.as_deref(),
            Some(&[15.0, 25.0, 35.0][..])
        );
    }
}
