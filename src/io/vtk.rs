//! VTK XML unstructured grid (`.vtu`) of the deformed network: one line cell per element,
//! the radius as point data for ParaView's tube filter, displacements and rotations.

use crate::model::Model;
use crate::solve::StaticSolution;
use std::fmt::Write;

/// The deformed network (positions x + u) as an ASCII `.vtu` document.
pub fn deformed_vtu(model: &Model, sol: &StaticSolution) -> String {
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
    for (nd, u) in model.nodes.iter().zip(&sol.displacements) {
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
    for u in &sol.displacements {
        let _ = writeln!(s, "{:e} {:e} {:e}", u[0], u[1], u[2]);
    }
    s.push_str("</DataArray>\n<DataArray type=\"Float64\" Name=\"rotation\" NumberOfComponents=\"3\" format=\"ascii\">\n");
    for u in &sol.displacements {
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
