//! Collections (`.pvd`): a stick/slip run's increments, and a model with its contacts.

use super::contacts::contact_points;
use super::document::VtkEncoding;
use super::network::{network_vtk, NetworkFormat};
use crate::contact::{ContactSet, ContactState};
use crate::model::Model;
use crate::solve::{ContactRecord, IncrementalSolution};
use std::fmt::Write;

/// A ParaView collection: for every increment the network `step_NNNN.vtp` (part 0) and the
/// contacts `contacts_NNNN.vtp` (part 1), with the load factor α as time.
pub fn series_pvd(sol: &IncrementalSolution) -> String {
    let mut s = collection_head();
    for r in &sol.increments {
        for (part, prefix) in ["step", "contacts"].iter().enumerate() {
            let _ = writeln!(
                s,
                "<DataSet timestep=\"{}\" group=\"\" part=\"{part}\" file=\"{}\"/>",
                r.alpha,
                step_file(prefix, r.step)
            );
        }
    }
    s.push_str("</Collection>\n</VTKFile>\n");
    s
}

/// `{prefix}_{step:04}.vtp`.
pub fn step_file(prefix: &str, step: usize) -> String {
    format!("{prefix}_{step:04}.vtp")
}

fn collection_head() -> String {
    String::from(
        "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\" \
         byte_order=\"LittleEndian\">\n<Collection>\n",
    )
}

/// The undeformed model for ParaView: the network (`.vtp`, the radius for the Tube filter) and
/// its contacts as found by the search (closed: state 1, open candidates: state 0, with the
/// initial gap), and a `.pvd` collection of the two (parts 0 and 1) naming them
/// `{stem}_fibers.vtp` and `{stem}_contacts.vtp`. Returns (network, contacts, collection).
pub fn model_vtk(
    model: &Model,
    stem: &str,
    encoding: VtkEncoding,
) -> Result<(String, String, String), crate::Error> {
    let network = network_vtk(
        model,
        &vec![[0.0; 6]; model.nodes.len()],
        NetworkFormat::PolyData,
        encoding,
    );
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
    let contacts = contact_points(&set.origins, &records, encoding);
    let mut pvd = collection_head();
    for (part, what) in ["fibers", "contacts"].iter().enumerate() {
        let _ = writeln!(
            pvd,
            "<DataSet timestep=\"0\" group=\"\" part=\"{part}\" file=\"{stem}_{what}.vtp\"/>"
        );
    }
    pvd.push_str("</Collection>\n</VTKFile>\n");
    Ok((network, contacts, pvd))
}
