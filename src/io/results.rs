//! Nodal results as CSV and JSON.

use crate::constraints::Reaction;
use crate::contact::ContactSide;
use crate::model::Model;
use crate::solve::{IncrementalSolution, StaticSolution};
use serde_json::{json, Map, Value};
use std::fmt::Write;

/// `node,ux,uy,uz,rx,ry,rz`, one line per node, full precision.
pub fn displacements_csv(model: &Model, displacements: &[[f64; 6]]) -> String {
    let mut s = String::from("node,ux [m],uy [m],uz [m],rx [rad],ry [rad],rz [rad]\n");
    for (n, u) in model.nodes.iter().zip(displacements) {
        let _ = writeln!(
            s,
            "{},{:e},{:e},{:e},{:e},{:e},{:e}",
            n.id, u[0], u[1], u[2], u[3], u[4], u[5]
        );
    }
    s
}

fn displacements_map(model: &Model, displacements: &[[f64; 6]]) -> Map<String, Value> {
    let mut disp = Map::new();
    for (n, u) in model.nodes.iter().zip(displacements) {
        disp.insert(n.id.to_string(), json!(u));
    }
    disp
}

fn reactions_json(model: &Model, reactions: &[Reaction]) -> Vec<Value> {
    reactions
        .iter()
        .map(|r| json!({"node": model.nodes[r.node].id, "dof": r.dof.name(), "value": r.value}))
        .collect()
}

/// The fields every result document starts with: model, units, sizes, displacements keyed by
/// node id, reactions.
fn result_document(
    model: &Model,
    displacements: &[[f64; 6]],
    reactions: &[Reaction],
) -> Map<String, Value> {
    let mut doc = Map::new();
    doc.insert("model".into(), json!(model.name));
    doc.insert("units".into(), json!("SI (m, N, rad)"));
    doc.insert("nodes".into(), json!(model.nodes.len()));
    doc.insert("fibers".into(), json!(model.fibers.len()));
    doc.insert("elements".into(), json!(model.elements().len()));
    doc.insert(
        "displacements".into(),
        Value::Object(displacements_map(model, displacements)),
    );
    doc.insert("reactions".into(), json!(reactions_json(model, reactions)));
    doc
}

/// One JSON document: `displacements` keyed by node id, `reactions`, and the solver report.
pub fn solution_json(model: &Model, sol: &StaticSolution) -> Value {
    let mut doc = result_document(model, &sol.displacements, &sol.reactions);
    doc.insert("solver".into(), json!(sol.summary));
    Value::Object(doc)
}

fn side_json(model: &Model, side: ContactSide) -> Value {
    match side {
        ContactSide::Node(n) => json!({"node": model.nodes[n].id}),
        ContactSide::Point { element, xi } => {
            let e = model.elements()[element];
            json!({"fiber": model.fibers[e.fiber].id, "nodes": [model.nodes[e.nodes[0]].id, model.nodes[e.nodes[1]].id], "xi": xi})
        }
    }
}

/// `step,alpha,iterations,factorizations,open,stick,slip,load_*,reaction_*`, one line per
/// increment.
pub fn increments_csv(sol: &IncrementalSolution) -> String {
    let mut s = String::from(
        "step,alpha [-],iterations,factorizations,open,stick,slip,\
         load_fx [N],load_fy [N],load_fz [N],load_mx [N*m],load_my [N*m],load_mz [N*m],\
         reaction_fx [N],reaction_fy [N],reaction_fz [N],\
         reaction_mx [N*m],reaction_my [N*m],reaction_mz [N*m]\n",
    );
    for r in &sol.increments {
        let _ = write!(
            s,
            "{},{},{},{},{},{},{}",
            r.step, r.alpha, r.iterations, r.factorizations, r.open, r.stick, r.slip
        );
        for v in r.applied_load.iter().chain(&r.reaction) {
            let _ = write!(s, ",{v:e}");
        }
        s.push('\n');
    }
    s
}

/// `step,alpha,contact,fiber_a,fiber_b,x,y,z,state,gap,normal_force,tangential_force,friction_bound`:
/// every contact at every increment.
pub fn contacts_csv(sol: &IncrementalSolution) -> String {
    let mut s = String::from(
        "step,alpha [-],contact,fiber_a,fiber_b,x [m],y [m],z [m],state,gap [m],\
         normal_force [N],tangential_force [N],friction_bound [N]\n",
    );
    for (inc, records) in sol.increments.iter().zip(&sol.contact_results) {
        for (i, (o, c)) in sol.contacts.origins.iter().zip(records).enumerate() {
            let _ = writeln!(
                s,
                "{},{},{},{},{},{:e},{:e},{:e},{},{:e},{:e},{:e},{:e}",
                inc.step,
                inc.alpha,
                i + 1,
                o.fibers[0],
                o.fibers[1],
                o.point[0],
                o.point[1],
                o.point[2],
                c.state.name(),
                c.gap,
                c.normal_force,
                c.tangential_magnitude,
                c.friction_bound
            );
        }
    }
    s
}

/// The incremental solution as one JSON document: final `displacements` and `reactions`,
/// `increments` (one record per increment), `contacts` (every pair at the last increment) and
/// `initial_penetration`.
pub fn incremental_json(model: &Model, sol: &IncrementalSolution) -> Value {
    let last = sol.displacements.last().map(|d| &d[..]).unwrap_or(&[]);
    let contacts: Vec<Value> = match sol.contact_results.last() {
        Some(records) => sol
            .contacts
            .origins
            .iter()
            .zip(records)
            .enumerate()
            .map(|(i, (o, c))| {
                json!({
                    "contact": i + 1,
                    "origin": o.kind,
                    "a": side_json(model, o.sides[0]),
                    "b": side_json(model, o.sides[1]),
                    "point": o.point,
                    "state": c.state.name(),
                    "gap": c.gap,
                    "normal_force": c.normal_force,
                    "tangential_force": c.tangential_force,
                    "tangential_magnitude": c.tangential_magnitude,
                    "friction_bound": c.friction_bound,
                })
            })
            .collect(),
        None => Vec::new(),
    };
    let p = sol.contacts.penetration;
    let mut doc = result_document(model, last, &sol.reactions);
    doc.insert("increments".into(), json!(sol.increments));
    doc.insert("contacts".into(), json!(contacts));
    doc.insert(
        "initial_penetration".into(),
        json!({"count": p.count, "worst_overlap": p.worst_overlap, "adjusted": p.adjusted}),
    );
    Value::Object(doc)
}
