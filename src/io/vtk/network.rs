//! The fiber network: one poly line per fiber through its nodes (reference coordinates), with
//! the radius, displacement, rotation and node id as point data and the fiber id as cell data.

use super::document::{Document, VtkEncoding};
use crate::model::Model;

/// The dataset a network file holds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum NetworkFormat {
    /// `.vtp` PolyData: ParaView's *Tube* filter takes its lines directly.
    PolyData,
    /// `.vtu` UnstructuredGrid with poly-line cells (*Extract Surface* before *Tube*).
    UnstructuredGrid,
}

/// What every network file says about its points.
pub(super) const REFERENCE_POINTS: &str = "Points are the reference (undeformed) coordinates; \
    apply Warp By Vector with the point data \"displacement\" to see the deformed network. \
    Units: m and rad.";

/// The network of `model` with nodal `displacements` (six per node: three translations, three
/// rotations) as a VTK document of `format`.
pub fn network_vtk(
    model: &Model,
    displacements: &[[f64; 6]],
    format: NetworkFormat,
    encoding: VtkEncoding,
) -> String {
    let n = model.nodes.len();
    let lines = model.fibers.len();
    let kind = match format {
        NetworkFormat::PolyData => "PolyData",
        NetworkFormat::UnstructuredGrid => "UnstructuredGrid",
    };
    let mut d = Document::new(kind, REFERENCE_POINTS, encoding.binary(n));
    d.open(&match format {
        NetworkFormat::PolyData => {
            format!("Piece NumberOfPoints=\"{n}\" NumberOfLines=\"{lines}\"")
        }
        NetworkFormat::UnstructuredGrid => {
            format!("Piece NumberOfPoints=\"{n}\" NumberOfCells=\"{lines}\"")
        }
    });
    d.open("Points");
    let points: Vec<f64> = model.nodes.iter().flat_map(|nd| nd.x).collect();
    d.array("Points", 3, &points);
    d.close("Points");
    let cells = match format {
        NetworkFormat::PolyData => "Lines",
        NetworkFormat::UnstructuredGrid => "Cells",
    };
    d.open(cells);
    let connectivity: Vec<i64> = model
        .fibers
        .iter()
        .flat_map(|f| f.nodes.iter().map(|&k| k as i64))
        .collect();
    let offsets: Vec<i64> = model
        .fibers
        .iter()
        .scan(0i64, |end, f| {
            *end += f.nodes.len() as i64;
            Some(*end)
        })
        .collect();
    d.array("connectivity", 1, &connectivity);
    d.array("offsets", 1, &offsets);
    if format == NetworkFormat::UnstructuredGrid {
        // VTK_POLY_LINE.
        d.array("types", 1, &vec![4u8; lines]);
    }
    d.close(cells);
    d.open("PointData Scalars=\"radius\" Vectors=\"displacement\"");
    d.array("radius", 1, &node_radius(model));
    let part = |range: std::ops::Range<usize>| -> Vec<f64> {
        displacements
            .iter()
            .flat_map(|u| u[range.clone()].to_vec())
            .collect()
    };
    d.array("displacement", 3, &part(0..3));
    d.array("rotation", 3, &part(3..6));
    let ids: Vec<i64> = model.nodes.iter().map(|nd| nd.id as i64).collect();
    d.array("node_id", 1, &ids);
    d.close("PointData");
    d.open("CellData Scalars=\"fiber_id\"");
    let fiber_ids: Vec<i64> = model.fibers.iter().map(|f| f.id as i64).collect();
    d.array("fiber_id", 1, &fiber_ids);
    d.close("CellData");
    d.finish()
}

/// Per node, the largest radius of the fibers through it (the Tube filter's radius).
fn node_radius(model: &Model) -> Vec<f64> {
    let mut radius = vec![0.0f64; model.nodes.len()];
    for f in &model.fibers {
        for &k in &f.nodes {
            radius[k] = radius[k].max(f.section.radius);
        }
    }
    radius
}
