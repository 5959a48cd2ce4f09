//! The flags of point input (LAS/LAZ, XYZ/CSV text, OGR layers), shared by `mesh` and `verify`.

use std::path::PathBuf;

use clap::{Args, ValueEnum};
use tinsmith_pipeline::{Duplicates, PointChoices};

/// The flags of point input (LAS/LAZ, XYZ/CSV text), shared by `mesh` and `verify`.
#[derive(Debug, Args)]
pub struct PointArgs {
    /// LAS classes to keep, comma-separated [default: 2 (ground) when the file has any
    /// ground point, else every class].
    #[arg(
        long,
        value_name = "C,..",
        value_delimiter = ',',
        help_heading = "Point input"
    )]
    pub classes: Vec<u8>,
    /// Drop LAS points flagged withheld.
    #[arg(long, help_heading = "Point input")]
    pub no_withheld: bool,
    /// Which height a position with several points keeps (see docs/cli.md, "Point
    /// input", for how the default was chosen).
    #[arg(long, value_enum, default_value_t = DuplicatesArg::Lowest, help_heading = "Point input")]
    pub duplicates: DuplicatesArg,
    /// Keep the segments of this OGR line or polygon layer (GeoPackage, Shapefile,
    /// GeoJSON, FlatGeobuf...) as TIN edges, in the input's CRS. Lines with Z keep their
    /// heights, 2D lines take the points'; vertices go on the points' lattice; crossing
    /// lines are split where they cross. A raster's valid samples are then its points.
    /// With verify: check every segment is a chain of mesh edges.
    #[arg(long, value_name = "FILE", help_heading = "Point input")]
    pub breaklines: Option<PathBuf>,
    /// The TIN's outline and holes, an OGR polygon layer in the input's CRS, kept as
    /// edges; points (or a raster's samples) outside are dropped (counted in the report),
    /// and `verify` measures only the points inside.
    #[arg(long, value_name = "FILE", help_heading = "Point input")]
    pub boundary: Option<PathBuf>,
    /// OGR point layers (GeoPackage, Shapefile, FlatGeobuf) only: the attribute holding
    /// the heights [default: the points' Z].
    #[arg(long, value_name = "NAME", help_heading = "Point input")]
    pub z_field: Option<String>,
}

#[derive(Debug, Clone, Copy, ValueEnum)]
pub enum DuplicatesArg {
    /// The lowest height.
    Lowest,
    /// The highest height.
    Highest,
    /// The mean of the heights.
    Mean,
    /// The first in file order.
    First,
}

impl PointArgs {
    /// The point choices these flags ask for (`crs` from `mesh --crs`).
    pub fn choices(&self, crs: Option<String>) -> PointChoices {
        let mut choices = PointChoices::default();
        choices.classes = (!self.classes.is_empty()).then(|| self.classes.clone());
        choices.no_withheld = self.no_withheld;
        choices.duplicates = match self.duplicates {
            DuplicatesArg::Lowest => Duplicates::Lowest,
            DuplicatesArg::Highest => Duplicates::Highest,
            DuplicatesArg::Mean => Duplicates::Mean,
            DuplicatesArg::First => Duplicates::First,
        };
        choices.crs = crs;
        choices.breaklines = self.breaklines.clone();
        choices.boundary = self.boundary.clone();
        choices.z_field = self.z_field.clone();
        choices
    }
}
