//! VTK XML unstructured grid (`.vtu`) of the deformed network: one line cell per element,
//! the radius as point data for ParaView's tube filter, displacements and rotations.

use crate::contact::{ContactOrigin, ContactSet, ContactState};
use crate::model::Model;
use crate::solve::{ContactRecord, IncrementalSolution};
use std::fmt::Write;

/// The deformed network (positions x + u) as an ASCII `.vtu` document.
pub fn deformed_vtu(model: &Model, displacements: &[[f64; 6]]) -> String {
    let n = model.nodes.len();
    let els = model.elements();
    let mut radius = vec![0.0f64; n];
    for e in els {
        let r = model.fibers[e.fiber].section.radius;
        for &nd in &e.nodes {
            radius[nd] = radius[nd].max(r);
        }
    }
    let mut s = String::with_capacity(200 * n + 100 * els.len());
    s.push_str("<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\">\n<UnstructuredGrid>\n");
    let _ = writeln!(
        s,
        "<Piece NumberOfPoints=\"{n}\" NumberOfCells=\"{}\">",
        els.len()
    );
    s.push_str(
        "<Points>\n<DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"ascii\">\n",
    );
    for (nd, u) in model.nodes.iter().zip(displacements) {
        let _ = writeln!(
            s,
            "{:e} {:e} {:e}",
            nd.x[0] + u[0],
            nd.x[1] + u[1],
            nd.x[2] + u[2]
        );
    }
    s.push_str("</DataArray>\n</Points>\n<Cells>\n<DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">\n");
    for e in els {
        let _ = writeln!(s, "{} {}", e.nodes[0], e.nodes[1]);
    }
    s.push_str("</DataArray>\n<DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">\n");
    for k in 0..els.len() {
        let _ = writeln!(s, "{}", 2 * (k + 1));
    }
    s.push_str("</DataArray>\n<DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">\n");
    for _ in els {
        s.push_str("3\n");
    }
    s.push_str("</DataArray>\n</Cells>\n<PointData Scalars=\"radius\" Vectors=\"displacement\">\n");
    s.push_str("<DataArray type=\"Float64\" Name=\"radius\" format=\"ascii\">\n");
    for r in &radius {
        let _ = writeln!(s, "{r:e}");
    }
    s.push_str("</DataArray>\n<DataArray type=\"Float64\" Name=\"displacement\" NumberOfComponents=\"3\" format=\"ascii\">\n");
    for u in displacements {
        let _ = writeln!(s, "{:e} {:e} {:e}", u[0], u[1], u[2]);
    }
    s.push_str("</DataArray>\n<DataArray type=\"Float64\" Name=\"rotation\" NumberOfComponents=\"3\" format=\"ascii\">\n");
    for u in displacements {
        let _ = writeln!(s, "{:e} {:e} {:e}", u[3], u[4], u[5]);
    }
    s.push_str("</DataArray>\n<DataArray type=\"Int64\" Name=\"node_id\" format=\"ascii\">\n");
    for nd in &model.nodes {
        let _ = writeln!(s, "{}", nd.id);
    }
    s.push_str("</DataArray>\n</PointData>\n<CellData Scalars=\"fiber_id\">\n<DataArray type=\"Int64\" Name=\"fiber_id\" format=\"ascii\">\n");
    for e in els {
        let _ = writeln!(s, "{}", model.fibers[e.fiber].id);
    }
    s.push_str("</DataArray>\n</CellData>\n</Piece>\n</UnstructuredGrid>\n</VTKFile>\n");
    s
}

/// The contact points of increment `step` (0-based) as vertex cells with point data `state`
/// (0 open, 1 stick, 2 slip), `normal_force`, `tangential_force` (vector) and `gap`.
pub fn contacts_vtu(sol: &IncrementalSolution, step: usize) -> String {
    let records = sol.contact_results.get(step).map(|r| &r[..]).unwrap_or(&[]);
    contact_points_vtu(&sol.contacts.origins, records)
}

/// Contact points (side I) with their records as vertex cells.
fn contact_points_vtu(origins: &[ContactOrigin], records: &[ContactRecord]) -> String {
    let n = records.len().min(origins.len());
    let mut s = String::with_capacity(200 * n + 1000);
    s.push_str("<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\">\n<UnstructuredGrid>\n");
    let _ = writeln!(s, "<Piece NumberOfPoints=\"{n}\" NumberOfCells=\"{n}\">");
    s.push_str(
        "<Points>\n<DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"ascii\">\n",
    );
    for o in &origins[..n] {
        let _ = writeln!(s, "{:e} {:e} {:e}", o.point[0], o.point[1], o.point[2]);
    }
    s.push_str("</DataArray>\n</Points>\n<Cells>\n<DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">\n");
    for k in 0..n {
        let _ = writeln!(s, "{k}");
    }
    s.push_str("</DataArray>\n<DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">\n");
    for k in 0..n {
        let _ = writeln!(s, "{}", k + 1);
    }
    s.push_str("</DataArray>\n<DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">\n");
    for _ in 0..n {
        s.push_str("1\n");
    }
    s.push_str("</DataArray>\n</Cells>\n<PointData Scalars=\"state\" Vectors=\"tangential_force\">\n<DataArray type=\"Int32\" Name=\"state\" format=\"ascii\">\n");
    for r in records {
        let _ = writeln!(s, "{}", r.state as i32);
    }
    s.push_str(
        "</DataArray>\n<DataArray type=\"Float64\" Name=\"normal_force\" format=\"ascii\">\n",
    );
    for r in records {
        let _ = writeln!(s, "{:e}", r.normal_force);
    }
    s.push_str("</DataArray>\n<DataArray type=\"Float64\" Name=\"gap\" format=\"ascii\">\n");
    for r in records {
        let _ = writeln!(s, "{:e}", r.gap);
    }
    s.push_str("</DataArray>\n<DataArray type=\"Float64\" Name=\"tangential_force\" NumberOfComponents=\"3\" format=\"ascii\">\n");
    for r in records {
        let t = r.tangential_force;
        let _ = writeln!(s, "{:e} {:e} {:e}", t[0], t[1], t[2]);
    }
    s.push_str("</DataArray>\n</PointData>\n</Piece>\n</UnstructuredGrid>\n</VTKFile>\n");
    s
}

/// A ParaView collection: for every increment the network `step_NNNN.vtu` (part 0) and the
/// contacts `contacts_NNNN.vtu` (part 1), with the load factor α as time.
pub fn series_pvd(sol: &IncrementalSolution) -> String {
    let mut s = String::from("<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n<Collection>\n");
    for r in &sol.increments {
        let _ = writeln!(
            s,
            "<DataSet timestep=\"{}\" group=\"\" part=\"0\" file=\"{}\"/>",
            r.alpha,
            step_file("step", r.step)
        );
        let _ = writeln!(
            s,
            "<DataSet timestep=\"{}\" group=\"\" part=\"1\" file=\"{}\"/>",
            r.alpha,
            step_file("contacts", r.step)
        );
    }
    s.push_str("</Collection>\n</VTKFile>\n");
    s
}

/// `{prefix}_{step:04}.vtu`.
pub fn step_file(prefix: &str, step: usize) -> String {
    format!("{prefix}_{step:04}.vtu")
}

/// The undeformed model for ParaView: the network (`.vtu` with the radius for the tube filter)
/// and its contacts as found by the search (closed: state 1, open candidates: state 0, with the
/// initial gap), and a `.pvd` collection of the two (parts 0 and 1) naming them
/// `{stem}_fibers.vtu` and `{stem}_contacts.vtu`. Returns (network, contacts, collection).
pub fn model_vtk(model: &Model, stem: &str) -> Result<(String, String, String), crate::Error> {
    let network = deformed_vtu(model, &vec![[0.0; 6]; model.nodes.len()]);
    let periodic = match model.cell {
        Some(_) => Some(crate::cell::pair_boundary_nodes(model)?),
        None => None,
    };
    let set = match model.contact {
        Some(_) => ContactSet::build_with(model, periodic.as_ref())?,
        None => ContactSet::default(),
    };
    let records: Vec<ContactRecord> = set
        .pairs
        .iter()
        .map(|p| ContactRecord {
            state: if p.gap <= 0.0 {
                ContactState::Stick
            } else {
                ContactState::Open
            },
            gap: p.gap,
            normal_force: 0.0,
            tangential_force: [0.0; 3],
            tangential_magnitude: 0.0,
            friction_bound: 0.0,
            relative_tangential: [0.0; 3],
        })
        .collect();
    let contacts = contact_points_vtu(&set.origins, &records);
    let mut pvd = String::from("<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n<Collection>\n");
    for (part, what) in ["fibers", "contacts"].iter().enumerate() {
        let _ = writeln!(
            pvd,
            "<DataSet timestep=\"0\" group=\"\" part=\"{part}\" file=\"{stem}_{what}.vtu\"/>"
        );
    }
    pvd.push_str("</Collection>\n</VTKFile>\n");
    Ok((network, contacts, pvd))
}
