//! The periodic cell of an Abaqus input file, read from its `*EQUATION`s in the convention
//! TexGen writes: u(A) − u(B) − Σ c_D u(D) = 0 with D strain-driver nodes (node sets
//! `ConstraintsDriver0/1/2`, or any node that only appears in equations). Each driver's
//! equations must all join nodes one period apart, the same period; the x and y periods give
//! the cell, and the driver nodes are dropped from the model (they belong to no fiber).
//! Equations of two terms tie rotations (or translations) of paired nodes and are accepted
//! when the nodes lie a whole number of periods apart.

use super::InputError;
use crate::model::{CellSpec, NodeSpec};
use std::collections::{HashMap, HashSet};

/// A cell read from equations: its spec and the driver nodes to drop.
pub(super) struct EquationCell {
    pub cell: CellSpec,
    pub drivers: HashSet<u64>,
}

/// An `*EQUATION` as read: its line and its terms (node or node set, DOF 1–6, coefficient).
pub(super) type Equation = (usize, Vec<(String, usize, f64)>);

/// The cell of the equations, `None` when there are none.
pub(super) fn periodic_cell(
    nodes: &[NodeSpec],
    nsets: &HashMap<String, Vec<u64>>,
    equations: &[Equation],
    path: &str,
) -> Result<Option<EquationCell>, InputError> {
    if equations.is_empty() {
        return Ok(None);
    }
    let err = |line: usize, message: String| InputError::Syntax {
        path: path.into(),
        line,
        column: 1,
        message,
    };
    let pos: HashMap<u64, [f64; 3]> = nodes.iter().map(|n| (n.id, n.x)).collect();
    let members = |line: usize, target: &str| -> Result<Vec<u64>, InputError> {
        if let Ok(id) = target.parse::<u64>() {
            return Ok(vec![id]);
        }
        nsets.get(target).cloned().ok_or_else(|| {
            err(
                line,
                format!("*EQUATION: unknown node or node set \"{target}\""),
            )
        })
    };
    let mut drivers: HashSet<u64> = nsets
        .iter()
        .filter(|(name, _)| name.starts_with("CONSTRAINTSDRIVER"))
        .flat_map(|(_, ids)| ids.iter().copied())
        .collect();
    // Nodes that only ever appear as a third (or later) term are drivers too.
    for (line, terms) in equations {
        for (t, _, _) in terms.iter().skip(2) {
            drivers.extend(members(*line, t)?);
        }
    }
    // Period of each driver: the offset x_A − x_B of the pairs it drives.
    let mut period: HashMap<u64, ([f64; 3], usize)> = HashMap::new();
    let mut extent = 0.0f64;
    for x in pos.values() {
        extent = extent.max(x[0].abs()).max(x[1].abs());
    }
    let tol = 1e-9 * extent.max(f64::MIN_POSITIVE);
    for (line, terms) in equations {
        let line = *line;
        let (pairs, driven): (Vec<_>, Vec<_>) = terms.iter().partition(|(t, _, _)| {
            members(line, t).map_or(true, |m| m.iter().all(|id| !drivers.contains(id)))
        });
        if pairs.len() != 2
            || pairs[0].1 != pairs[1].1
            || pairs[0].2 != -pairs[1].2
            || pairs[0].2 == 0.0
        {
            return Err(err(
                line,
                "*EQUATION is not a periodic pair u(A) − u(B) [− drivers] = 0 of one DOF".into(),
            ));
        }
        let (a, b) = (members(line, &pairs[0].0)?, members(line, &pairs[1].0)?);
        if a.len() != b.len() {
            return Err(err(
                line,
                format!("*EQUATION node sets of {} and {} nodes", a.len(), b.len()),
            ));
        }
        let c = pairs[0].2;
        for (&na, &nb) in a.iter().zip(&b) {
            let (Some(xa), Some(xb)) = (pos.get(&na), pos.get(&nb)) else {
                return Err(err(
                    line,
                    format!("*EQUATION refers to undefined node {na} or {nb}"),
                ));
            };
            let offset = [xa[0] - xb[0], xa[1] - xb[1], xa[2] - xb[2]];
            if let [(d, _, cd)] = driven.as_slice() {
                let ids = members(line, d)?;
                let [id] = ids.as_slice() else {
                    return Err(err(
                        line,
                        format!("driver set {d} has {} nodes, not one", ids.len()),
                    ));
                };
                let sign = -cd / c;
                if (sign.abs() - 1.0).abs() > 1e-12 {
                    return Err(err(
                        line,
                        format!("driver coefficient {cd} is not ∓ that of the pair"),
                    ));
                }
                let o = offset.map(|v| v * sign);
                match period.get(id) {
                    Some((p, first)) => {
                        if (0..3).any(|k| (p[k] - o[k]).abs() > tol) {
                            return Err(err(
                                line,
                                format!(
                                    "nodes {na} and {nb} are {o:?} apart, but driver {id} was \
                                     given the period {p:?} on line {first}"
                                ),
                            ));
                        }
                    }
                    None => {
                        period.insert(*id, (o, line));
                    }
                }
            }
        }
    }
    let mut size = [None, None];
    for (id, (p, line)) in &period {
        let axis = match (p[0].abs() > tol, p[1].abs() > tol, p[2].abs() > tol) {
            (true, false, false) => 0,
            (false, true, false) => 1,
            _ => {
                return Err(err(
                    *line,
                    format!(
                        "driver {id} has the period {p:?}: only a rectangular cell with periods \
                         along x and y is supported"
                    ),
                ))
            }
        };
        if size[axis].is_some() {
            return Err(err(
                *line,
                format!("two drivers for the period along axis {axis}"),
            ));
        }
        size[axis] = Some(p[axis].abs());
    }
    let [Some(lx), Some(ly)] = size else {
        let line = equations[0].0;
        return Err(err(
            line,
            "the *EQUATIONs define no periods along both x and y".into(),
        ));
    };
    Ok(Some(EquationCell {
        cell: CellSpec {
            size: [lx, ly],
            origin: None,
            thickness: None,
            tolerance: None,
        },
        drivers,
    }))
}
