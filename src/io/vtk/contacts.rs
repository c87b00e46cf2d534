//! Contact points as vertices with their state and forces.

use super::document::{Document, VtkEncoding};
use crate::contact::ContactOrigin;
use crate::solve::{ContactRecord, IncrementalSolution};

/// The contact points of increment `step` (0-based) of `sol` as a `.vtp` of vertices with
/// point data `state` (0 open, 1 stick, 2 slip), `normal_force` (N), `gap` (m) and
/// `tangential_force` (N, a vector).
pub fn contacts_vtp(sol: &IncrementalSolution, step: usize, encoding: VtkEncoding) -> String {
    let records = sol.contact_results.get(step).map(|r| &r[..]).unwrap_or(&[]);
    contact_points(&sol.contacts.origins, records, encoding)
}

/// Contact points (side I, reference coordinates) with their records as vertices.
pub(super) fn contact_points(
    origins: &[ContactOrigin],
    records: &[ContactRecord],
    encoding: VtkEncoding,
) -> String {
    let n = records.len().min(origins.len());
    let (origins, records) = (&origins[..n], &records[..n]);
    let mut d = Document::new(
        "PolyData",
        "Contact points (side I) at their reference coordinates. Units: m, N.",
        encoding.binary(n),
    );
    d.open(&format!(
        "Piece NumberOfPoints=\"{n}\" NumberOfVerts=\"{n}\""
    ));
    d.open("Points");
    let points: Vec<f64> = origins.iter().flat_map(|o| o.point).collect();
    d.array("Points", 3, &points);
    d.close("Points");
    d.open("Verts");
    let ids: Vec<i64> = (0..n as i64).collect();
    d.array("connectivity", 1, &ids);
    let offsets: Vec<i64> = (1..=n as i64).collect();
    d.array("offsets", 1, &offsets);
    d.close("Verts");
    d.open("PointData Scalars=\"state\" Vectors=\"tangential_force\"");
    let states: Vec<i32> = records.iter().map(|r| r.state as i32).collect();
    d.array("state", 1, &states);
    let normal: Vec<f64> = records.iter().map(|r| r.normal_force).collect();
    d.array("normal_force", 1, &normal);
    let gap: Vec<f64> = records.iter().map(|r| r.gap).collect();
    d.array("gap", 1, &gap);
    let tangential: Vec<f64> = records.iter().flat_map(|r| r.tangential_force).collect();
    d.array("tangential_force", 3, &tangential);
    d.close("PointData");
    d.finish()
}
