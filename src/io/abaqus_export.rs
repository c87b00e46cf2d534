//! Abaqus `.inp` export of a model, read back exactly by [`parse_abaqus`](super::parse_abaqus).
//!
//! * Each fiber is one element set `FIBER-<id>` of two-node `B31` elements (numbered 1, 2, …
//!   fiber after fiber) with its own `*BEAM SECTION, SECTION=CIRC` (n1 chosen off every element
//!   axis of the fiber, irrelevant for a circular section).
//! * Materials: `*MATERIAL` with `*ELASTIC` E, ν (a material given by G is written with
//!   ν = E/2G − 1).
//! * Supports and loads: `*BOUNDARY` and `*CLOAD` in one `*STEP` / `*STATIC`.
//! * A periodic cell: the node pairing as `*EQUATION`s with strain-driver nodes in the
//!   convention TexGen writes — three extra nodes in the sets `ConstraintsDriver0/1/2` whose
//!   translations are the displacement differences across the x and y periods:
//!   u(slave) − u(master) − i u(Driver0) − j u(Driver1) = 0 for a slave shifted by (i, j)
//!   periods, DOFs 1–3; the rotations are equal, DOFs 4–6 (Driver2, the z period, is unused by
//!   a plate cell and kept for the convention).
//! * What Abaqus has no keyword for here — the contact settings, explicit contact pairs and the
//!   cell's own fields — goes into `** fibercell-…:` comment lines (JSON) that Abaqus ignores
//!   and fibercell reads back.

use crate::cell::pair_boundary_nodes;
use crate::model::{DofSet, ModelDescription};
use crate::{Error, Model};
use std::fmt::Write;

/// Comment prefixes of the fibercell-only settings.
pub(super) const CONTACT_COMMENT: &str = "** fibercell-contact:";
pub(super) const CELL_COMMENT: &str = "** fibercell-cell:";
pub(super) const PAIR_COMMENT: &str = "** fibercell-pair:";
/// Node sets of the strain drivers (TexGen's names).
pub(super) const DRIVER_SETS: [&str; 3] = [
    "ConstraintsDriver0",
    "ConstraintsDriver1",
    "ConstraintsDriver2",
];

fn json<T: serde::Serialize>(v: &T) -> Result<String, Error> {
    serde_json::to_string(v).map_err(|e| Error::InvalidOption(format!("Abaqus export: {e}")))
}

/// The model as an Abaqus input file. The model is validated first (and, for a cell, its
/// boundary nodes paired), so only a sound model is written.
pub fn to_abaqus(d: &ModelDescription) -> Result<String, Error> {
    let model = Model::from_description(d)?;
    for m in &d.materials {
        if m.name.contains([',', '\n', '*']) || m.name.trim() != m.name || m.name.is_empty() {
            return Err(Error::InvalidOption(format!(
                "Abaqus export: material name \"{}\" cannot be written (no commas, asterisks or \
                 surrounding blanks)",
                m.name
            )));
        }
    }
    let mut s = String::new();
    let w = &mut s;
    let _ = writeln!(w, "*HEADING");
    let _ = writeln!(
        w,
        "{}",
        d.name
            .as_deref()
            .unwrap_or("fibercell model")
            .replace('\n', " ")
    );
    let _ = writeln!(w, "** Written by fibercell {}.", env!("CARGO_PKG_VERSION"));
    if let Some(c) = &d.contact {
        let _ = writeln!(w, "{CONTACT_COMMENT} {}", json(c)?);
    }
    for p in &d.contacts {
        let _ = writeln!(w, "{PAIR_COMMENT} {}", json(p)?);
    }
    if let Some(c) = &d.cell {
        let _ = writeln!(w, "{CELL_COMMENT} {}", json(c)?);
    }
    let _ = writeln!(w, "*NODE");
    for n in &d.nodes {
        let _ = writeln!(w, "{}, {:?}, {:?}, {:?}", n.id, n.x[0], n.x[1], n.x[2]);
    }
    let mut eid = 0u64;
    for f in &d.fibers {
        let set = format!("FIBER-{}", f.id);
        let _ = writeln!(w, "*ELEMENT, TYPE=B31, ELSET={set}");
        for pair in f.nodes.windows(2) {
            eid += 1;
            let _ = writeln!(w, "{eid}, {}, {}", pair[0], pair[1]);
        }
        let _ = writeln!(
            w,
            "*BEAM SECTION, SECTION=CIRC, ELSET={set}, MATERIAL={}",
            f.material
        );
        let _ = writeln!(w, "{:?}", f.radius);
        let n1 = section_direction(&model, f);
        let _ = writeln!(w, "{:?}, {:?}, {:?}", n1[0], n1[1], n1[2]);
    }
    for m in &d.materials {
        let nu = match (m.poisson, m.shear) {
            (Some(nu), _) => nu,
            (None, Some(g)) => m.young / (2.0 * g) - 1.0,
            (None, None) => {
                return Err(Error::InvalidOption(format!(
                    "Abaqus export: material {} has neither ν nor G",
                    m.name
                )))
            }
        };
        let _ = writeln!(
            w,
            "*MATERIAL, NAME={}\n*ELASTIC\n{:?}, {:?}",
            m.name, m.young, nu
        );
    }
    if model.cell.is_some() {
        write_equations(w, &model, d)?;
    }
    if !d.supports.is_empty() || !d.loads.is_empty() {
        let _ = writeln!(w, "*STEP\n*STATIC");
        for sp in &d.supports {
            let _ = writeln!(w, "*BOUNDARY");
            for (a, b) in dof_ranges(&sp.dofs) {
                let _ = writeln!(w, "{}, {a}, {b}, {:?}", sp.node, sp.value);
            }
        }
        for l in &d.loads {
            let comps = l.force.iter().chain(&l.moment).enumerate();
            let nonzero: Vec<(usize, f64)> = comps
                .filter(|(_, v)| **v != 0.0)
                .map(|(k, v)| (k, *v))
                .collect();
            if nonzero.is_empty() {
                continue;
            }
            let _ = writeln!(w, "*CLOAD");
            for (k, v) in nonzero {
                let _ = writeln!(w, "{}, {}, {v:?}", l.node, k + 1);
            }
        }
        let _ = writeln!(w, "*END STEP");
    }
    Ok(s)
}

/// DOF ranges (Abaqus numbering 1–6) of a support's DOF sets.
fn dof_ranges(sets: &[DofSet]) -> Vec<(usize, usize)> {
    sets.iter()
        .map(|s| match s {
            DofSet::Translations => (1, 3),
            DofSet::Rotations => (4, 6),
            DofSet::All => (1, 6),
            one => {
                let k = one.dofs()[0].index() + 1;
                (k, k)
            }
        })
        .collect()
}

/// The direction least aligned with every element of the fiber, among the three coordinate
/// axes and the ten diagonals (normalized ±1 combinations): its largest |cos| to an element
/// is the smallest. A fiber bent along all three axes (up, across, along y) has every axis
/// parallel to some element, and Abaqus refuses an n1 along an element; a diagonal then serves.
fn section_direction(model: &Model, f: &crate::model::FiberSpec) -> [f64; 3] {
    let pos = |id: u64| model.node_index(id).map_or([0.0; 3], |i| model.nodes[i].x);
    let axes: Vec<[f64; 3]> = f
        .nodes
        .windows(2)
        .filter_map(|pair| {
            let (a, b) = (pos(pair[0]), pos(pair[1]));
            let t = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
            let l = (t[0] * t[0] + t[1] * t[1] + t[2] * t[2]).sqrt();
            (l > 0.0).then(|| t.map(|v| v / l))
        })
        .collect();
    let mut candidates: Vec<[f64; 3]> = vec![[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    let (r2, r3) = (0.5f64.sqrt(), (1.0f64 / 3.0).sqrt());
    for (i, j) in [(0, 1), (0, 2), (1, 2)] {
        for sign in [1.0, -1.0] {
            let mut d = [0.0; 3];
            d[i] = r2;
            d[j] = sign * r2;
            candidates.push(d);
        }
    }
    for (sy, sz) in [(1.0, 1.0), (1.0, -1.0), (-1.0, 1.0), (-1.0, -1.0)] {
        candidates.push([r3, sy * r3, sz * r3]);
    }
    let alignment = |d: &[f64; 3]| {
        axes.iter()
            .map(|t| (t[0] * d[0] + t[1] * d[1] + t[2] * d[2]).abs())
            .fold(0.0f64, f64::max)
    };
    candidates
        .into_iter()
        .min_by(|a, b| alignment(a).total_cmp(&alignment(b)))
        .unwrap_or([0.0, 0.0, 1.0])
}

/// The periodic pairing as TexGen-style `*EQUATION`s with three driver nodes.
fn write_equations(w: &mut String, model: &Model, d: &ModelDescription) -> Result<(), Error> {
    let p = pair_boundary_nodes(model)?;
    let first_driver = d.nodes.iter().map(|n| n.id).max().unwrap_or(0) + 1;
    for (k, set) in DRIVER_SETS.iter().enumerate() {
        let _ = writeln!(
            w,
            "*NODE, NSET={set}\n{}, 0.0, 0.0, 0.0",
            first_driver + k as u64
        );
    }
    for (slave, m) in p.master.iter().enumerate() {
        let Some((master, shift)) = *m else { continue };
        let (s_id, m_id) = (model.nodes[slave].id, model.nodes[master].id);
        for dof in 1..=6 {
            let mut terms = vec![(s_id.to_string(), 1.0), (m_id.to_string(), -1.0)];
            if dof <= 3 {
                for (axis, &i) in shift.iter().enumerate() {
                    if i != 0 {
                        terms.push((DRIVER_SETS[axis].to_string(), -f64::from(i)));
                    }
                }
            }
            let _ = writeln!(w, "*EQUATION\n{}", terms.len());
            let line: Vec<String> = terms
                .iter()
                .map(|(n, c)| format!("{n}, {dof}, {c:?}"))
                .collect();
            let _ = writeln!(w, "{}", line.join(", "));
        }
    }
    Ok(())
}
