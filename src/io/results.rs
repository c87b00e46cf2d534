//! Nodal results as CSV and JSON.

use crate::model::Model;
use crate::solve::StaticSolution;
use serde_json::{json, Map, Value};
use std::fmt::Write;

/// `node,ux,uy,uz,rx,ry,rz`, one line per node, full precision.
pub fn displacements_csv(model: &Model, sol: &StaticSolution) -> String {
    let mut s = String::from("node,ux,uy,uz,rx,ry,rz\n");
    for (n, u) in model.nodes.iter().zip(&sol.displacements) {
        let _ = writeln!(
            s,
            "{},{:e},{:e},{:e},{:e},{:e},{:e}",
            n.id, u[0], u[1], u[2], u[3], u[4], u[5]
        );
    }
    s
}

/// One JSON document: `displacements` keyed by node id, `reactions`, and the solver report.
pub fn solution_json(model: &Model, sol: &StaticSolution) -> Value {
    let mut disp = Map::new();
    for (n, u) in model.nodes.iter().zip(&sol.displacements) {
        disp.insert(n.id.to_string(), json!(u));
    }
    let reactions: Vec<Value> = sol
        .reactions
        .iter()
        .map(|r| json!({"node": model.nodes[r.node].id, "dof": r.dof.name(), "value": r.value}))
        .collect();
    json!({
        "model": model.name,
        "units": "SI (m, N, rad)",
        "nodes": model.nodes.len(),
        "fibers": model.fibers.len(),
        "elements": model.elements().len(),
        "displacements": disp,
        "reactions": reactions,
        "solver": sol.summary,
    })
}
