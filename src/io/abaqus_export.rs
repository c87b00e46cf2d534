//! Abaqus `.inp` export of a model, read back exactly by [`parse_abaqus`](super::parse_abaqus),
//! and its CalculiX flavour ([`InpFlavour::CalculiX`]), which `ccx` 2.20 runs.
//!
//! * Numbers fit the 20-character field both read ([`inp_number`]); the exact coordinates of
//!   the few nodes that had to be rounded follow in a `** fibercell-node:` comment.
//! * Each fiber is one element set `FIBER-<id>` of two-node `B31` elements (numbered 1, 2, …
//!   fiber after fiber) with its own `*BEAM SECTION, SECTION=CIRC` (n1 chosen off every element
//!   axis of the fiber, irrelevant for a circular section). CalculiX expands a beam into solid
//!   elements and takes a circular section only on quadratic beams: its flavour writes `B32`
//!   elements with a midside node each, and the section's data line as CalculiX reads it, the
//!   diameter (measured: a cantilever of radius r deflects as one with I = π r⁴/4 when 2r is
//!   written, 16 times more when r is).
//! * Materials: `*MATERIAL` with `*ELASTIC` E, ν (a material given by G is written with
//!   ν = E/2G − 1).
//! * Supports and loads: `*BOUNDARY` and `*CLOAD` in one `*STEP` / `*STATIC`, which requests
//!   the displacements and reactions of every node (`*NODE PRINT` to the `.dat` file, `*NODE
//!   FILE` to the results file).
//! * A periodic cell: the node pairing as `*EQUATION`s with strain-driver nodes in the
//!   convention TexGen writes — three extra nodes in the sets `ConstraintsDriver0/1/2` whose
//!   translations are the displacement differences across the x and y periods:
//!   u(slave) − u(master) − i u(Driver0) − j u(Driver1) = 0 for a slave shifted by (i, j)
//!   periods, DOFs 1–3; the rotations are equal, DOFs 4–6 (Driver2, the z period, is unused by
//!   a plate cell and kept for the convention). Equations name nodes by number. The CalculiX
//!   flavour adds a step that applies [`InpOptions::cell_strain`] through the drivers with the
//!   anchor node's translations fixed, and requests the drivers' displacements too.
//! * What Abaqus has no keyword for here — the contact settings, explicit contact pairs and the
//!   cell's own fields — goes into `** fibercell-…:` comment lines (JSON) that Abaqus ignores
//!   and fibercell reads back.

use super::inp_number::inp_number;
use crate::cell::{anchor_node, pair_boundary_nodes, Periodicity};
use crate::model::{DofSet, ModelDescription};
use crate::{Error, Model};
use std::fmt::Write;

/// The solver an input file is written for.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum InpFlavour {
    /// Abaqus, and fibercell's own round trip.
    #[default]
    Abaqus,
    /// CalculiX (`ccx`): quadratic `B32` beams with the section's diameter, and a cell step.
    CalculiX,
}

/// Options of [`to_inp`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct InpOptions {
    pub flavour: InpFlavour,
    /// The macroscopic strain the CalculiX flavour's step applies to a periodic cell, membrane
    /// only (ε11, ε22, γ12; default ε11 = 10⁻³): curvatures would need rotation drivers.
    pub cell_strain: crate::cell::MacroStrain,
}

impl Default for InpOptions {
    fn default() -> Self {
        InpOptions {
            flavour: InpFlavour::Abaqus,
            cell_strain: [1e-3, 0.0, 0.0, 0.0, 0.0, 0.0],
        }
    }
}

/// Comment prefixes of the fibercell-only settings.
pub(super) const CONTACT_COMMENT: &str = "** fibercell-contact:";
pub(super) const CELL_COMMENT: &str = "** fibercell-cell:";
pub(super) const PAIR_COMMENT: &str = "** fibercell-pair:";
/// The exact coordinates of a node whose `*NODE` line had to round them: `{"id":…,"x":[…]}`.
pub(super) const NODE_COMMENT: &str = "** fibercell-node:";
/// The node set of the model's nodes, for output requests.
const ALL_NODES: &str = "FIBERCELL-NODES";
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
    to_inp(d, &InpOptions::default())
}

/// The model as an input file of `opts.flavour` (see the module documentation).
pub fn to_inp(d: &ModelDescription, opts: &InpOptions) -> Result<String, Error> {
    let model = Model::from_description(d)?;
    check_material_names(d)?;
    let calculix = opts.flavour == InpFlavour::CalculiX;
    let cell = match model.cell {
        Some(_) => Some(pair_boundary_nodes(&model)?),
        None => None,
    };
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
    write_nodes(w, d)?;
    // CalculiX's midside nodes, numbered after the nodes and the three drivers.
    let mut last_node = first_driver(d) + 2;
    let mut eid = 0u64;
    for f in &d.fibers {
        let set = format!("FIBER-{}", f.id);
        let elements = f.nodes.windows(2);
        if calculix {
            let _ = writeln!(w, "*NODE");
            for (k, pair) in elements.clone().enumerate() {
                let (a, b) = (node_x(&model, pair[0]), node_x(&model, pair[1]));
                let mid = [0, 1, 2].map(|c| inp_number(0.5 * (a[c] + b[c])));
                let id = last_node + 1 + k as u64;
                let _ = writeln!(w, "{id}, {}, {}, {}", mid[0], mid[1], mid[2]);
            }
        }
        let kind = if calculix { "B32" } else { "B31" };
        let _ = writeln!(w, "*ELEMENT, TYPE={kind}, ELSET={set}");
        for pair in elements {
            eid += 1;
            if calculix {
                last_node += 1;
                let _ = writeln!(w, "{eid}, {}, {last_node}, {}", pair[0], pair[1]);
            } else {
                let _ = writeln!(w, "{eid}, {}, {}", pair[0], pair[1]);
            }
        }
        let _ = writeln!(
            w,
            "*BEAM SECTION, SECTION=CIRC, ELSET={set}, MATERIAL={}",
            f.material
        );
        let size = if calculix { 2.0 * f.radius } else { f.radius };
        let _ = writeln!(w, "{}", inp_number(size));
        let n1 = section_direction(&model, f)?.map(inp_number);
        let _ = writeln!(w, "{}, {}, {}", n1[0], n1[1], n1[2]);
    }
    write_materials(w, d)?;
    if let Some(p) = &cell {
        write_equations(w, &model, d, p);
    }
    let loaded = !d.supports.is_empty() || !d.loads.is_empty();
    if loaded || (cell.is_some() && calculix) {
        let _ = writeln!(w, "*NSET, NSET={ALL_NODES}");
        for ids in d.nodes.chunks(16) {
            let ids: Vec<String> = ids.iter().map(|n| n.id.to_string()).collect();
            let _ = writeln!(w, "{}", ids.join(", "));
        }
    }
    match &cell {
        Some(p) if calculix => write_cell_step(w, &model, d, p, opts.cell_strain)?,
        _ if loaded => write_step(w, d),
        _ => {}
    }
    Ok(s)
}

/// Material names must survive the keyword line.
fn check_material_names(d: &ModelDescription) -> Result<(), Error> {
    for m in &d.materials {
        if m.name.contains([',', '\n', '*']) || m.name.trim() != m.name || m.name.is_empty() {
            return Err(Error::InvalidOption(format!(
                "Abaqus export: material name \"{}\" cannot be written (no commas, asterisks or \
                 surrounding blanks)",
                m.name
            )));
        }
    }
    Ok(())
}

/// The coordinates of node `id` of a validated model.
fn node_x(model: &Model, id: u64) -> [f64; 3] {
    model.node_index(id).map_or([0.0; 3], |i| model.nodes[i].x)
}

/// `*NODE`, and the exact coordinates of the nodes it rounds in comments.
fn write_nodes(w: &mut String, d: &ModelDescription) -> Result<(), Error> {
    let _ = writeln!(w, "*NODE");
    let mut rounded = Vec::new();
    for n in &d.nodes {
        let x = n.x.map(inp_number);
        if x.iter().zip(&n.x).any(|(s, v)| s.parse::<f64>() != Ok(*v)) {
            rounded.push(n);
        }
        let _ = writeln!(w, "{}, {}, {}, {}", n.id, x[0], x[1], x[2]);
    }
    for n in rounded {
        let exact = serde_json::json!({ "id": n.id, "x": n.x });
        let _ = writeln!(w, "{NODE_COMMENT} {}", json(&exact)?);
    }
    Ok(())
}

/// `*MATERIAL` with `*ELASTIC` E, ν of every material.
fn write_materials(w: &mut String, d: &ModelDescription) -> Result<(), Error> {
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
            "*MATERIAL, NAME={}\n*ELASTIC\n{}, {}",
            m.name,
            inp_number(m.young),
            inp_number(nu)
        );
    }
    Ok(())
}

/// The step of the supports and loads, with its output requests.
fn write_step(w: &mut String, d: &ModelDescription) {
    let _ = writeln!(w, "*STEP\n*STATIC");
    for sp in &d.supports {
        let _ = writeln!(w, "*BOUNDARY");
        for (a, b) in dof_ranges(&sp.dofs) {
            let _ = writeln!(w, "{}, {a}, {b}, {}", sp.node, inp_number(sp.value));
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
            let _ = writeln!(w, "{}, {}, {}", l.node, k + 1, inp_number(v));
        }
    }
    write_output_requests(w, &[ALL_NODES]);
    let _ = writeln!(w, "*END STEP");
}

/// Displacements and reactions of the node sets `sets` to the `.dat` file, and of every node
/// to the results file.
fn write_output_requests(w: &mut String, sets: &[&str]) {
    for set in sets {
        let _ = writeln!(w, "*NODE PRINT, NSET={set}\nU, RF");
    }
    let _ = writeln!(w, "*NODE FILE\nU, RF");
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
/// Should every one of them lie within 1° of some element, 2,000 directions spread over the
/// sphere are searched; a fiber with an element within 10⁻⁴ rad of each is an error (no n1
/// for one section exists).
fn section_direction(model: &Model, f: &crate::model::FiberSpec) -> Result<[f64; 3], Error> {
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
    let best = |candidates: Vec<[f64; 3]>| {
        candidates
            .into_iter()
            .map(|d| (alignment(&d), d))
            .min_by(|a, b| a.0.total_cmp(&b.0))
            .unwrap_or((0.0, [0.0, 0.0, 1.0]))
    };
    let (mut worst, mut n1) = best(candidates);
    if worst > 1.0f64.to_radians().cos() {
        // A Fibonacci lattice on the half sphere (n1 and −n1 are the same section plane).
        let golden = std::f64::consts::PI * (3.0 - 5.0f64.sqrt());
        let lattice: Vec<[f64; 3]> = (0..2000)
            .map(|k| {
                let z = 1.0 - (k as f64 + 0.5) / 2000.0;
                let r = (1.0 - z * z).sqrt();
                let phi = golden * k as f64;
                [r * phi.cos(), r * phi.sin(), z]
            })
            .collect();
        (worst, n1) = best(lattice);
    }
    if worst > 1.0 - 0.5e-8 {
        return Err(Error::InvalidOption(format!(
            "Abaqus export: fiber {} has elements along every direction, so no beam-section \
             direction n1 is off all of them: split the fiber",
            f.id
        )));
    }
    Ok(n1)
}

/// The number of the first strain-driver node: after the model's nodes.
fn first_driver(d: &ModelDescription) -> u64 {
    d.nodes.iter().map(|n| n.id).max().unwrap_or(0) + 1
}

/// The periodic pairing `p` as TexGen-style `*EQUATION`s with three driver nodes.
fn write_equations(w: &mut String, model: &Model, d: &ModelDescription, p: &Periodicity) {
    let first_driver = first_driver(d);
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
            let mut terms = vec![(s_id, 1.0), (m_id, -1.0)];
            if dof <= 3 {
                for (axis, &i) in shift.iter().enumerate() {
                    if i != 0 {
                        terms.push((first_driver + axis as u64, -f64::from(i)));
                    }
                }
            }
            let _ = writeln!(w, "*EQUATION\n{}", terms.len());
            let line: Vec<String> = terms
                .iter()
                .map(|(n, c)| format!("{n}, {dof}, {}", inp_number(*c)))
                .collect();
            let _ = writeln!(w, "{}", line.join(", "));
        }
    }
}

/// The CalculiX step of a cell: the membrane strain `strain` (ε11, ε22, γ12, …) through the
/// drivers — u(D0) = L1 (ε11, ε12, 0), u(D1) = L2 (ε12, ε22, 0), ε12 = γ12/2, D2 fixed — and
/// the anchor node's translations fixed; the drivers' displacements requested.
fn write_cell_step(
    w: &mut String,
    model: &Model,
    d: &ModelDescription,
    p: &Periodicity,
    strain: crate::cell::MacroStrain,
) -> Result<(), Error> {
    if strain[3..].iter().any(|&k| k != 0.0) || strain.iter().any(|v| !v.is_finite()) {
        return Err(Error::InvalidOption(format!(
            "CalculiX export: the cell step applies finite membrane strains (e11, e22, g12) \
             only, not {strain:?}"
        )));
    }
    let anchor = model.nodes[anchor_node(model, p)?].id;
    let [l1, l2] = p.geometry.size;
    let [e11, e22, g12, ..] = strain;
    let e12 = 0.5 * g12;
    let first = first_driver(d);
    let _ = writeln!(w, "*STEP\n*STATIC\n*BOUNDARY\n{anchor}, 1, 3, 0.0");
    for (k, u) in [[e11 * l1, e12 * l1], [e12 * l2, e22 * l2], [0.0, 0.0]]
        .iter()
        .enumerate()
    {
        let node = first + k as u64;
        let _ = writeln!(w, "{node}, 1, 1, {}", inp_number(u[0]));
        let _ = writeln!(w, "{node}, 2, 2, {}", inp_number(u[1]));
        let _ = writeln!(w, "{node}, 3, 3, 0.0");
    }
    let mut sets = vec![ALL_NODES];
    sets.extend(DRIVER_SETS.iter().take(2));
    write_output_requests(w, &sets);
    let _ = writeln!(w, "*END STEP");
    Ok(())
}
