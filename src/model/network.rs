//! The validated [`Model`].

use super::contact_settings::{check_pair, check_settings, ContactSettings, ExplicitContact};
use super::ContactSide;
use super::{
    CellSpec, ContactPairSpec, ContactSpec, Dof, Material, ModelDescription, ModelError, Section,
    SideSpec,
};
use std::collections::HashMap;

/// A node.
#[derive(Clone, Debug, PartialEq)]
pub struct Node {
    /// Id from the model file.
    pub id: u64,
    /// Position (m).
    pub x: [f64; 3],
}

/// A fiber: a polyline of nodes with one section and one material.
#[derive(Clone, Debug, PartialEq)]
pub struct Fiber {
    /// Id from the model file.
    pub id: u64,
    /// Node indices (into [`Model::nodes`]) along the fiber.
    pub nodes: Vec<usize>,
    /// Cross-section.
    pub section: Section,
    /// Index into [`Model::materials`].
    pub material: usize,
}

/// A 2-node frame element: one segment of a fiber.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Element {
    /// Index of the fiber.
    pub fiber: usize,
    /// First and second node index (local x runs from the first to the second).
    pub nodes: [usize; 2],
}

/// A prescribed DOF.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Support {
    /// Node index.
    pub node: usize,
    /// DOF.
    pub dof: Dof,
    /// Prescribed value (m or rad).
    pub value: f64,
}

/// A nodal force or moment component.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Load {
    /// Node index.
    pub node: usize,
    /// DOF it acts along.
    pub dof: Dof,
    /// Force (N) or moment (N·m).
    pub value: f64,
}

/// A validated fiber network.
#[derive(Clone, Debug, PartialEq)]
pub struct Model {
    /// Title.
    pub name: Option<String>,
    /// Nodes.
    pub nodes: Vec<Node>,
    /// Materials.
    pub materials: Vec<Material>,
    /// Fibers.
    pub fibers: Vec<Fiber>,
    /// Prescribed DOFs (one entry per DOF).
    pub supports: Vec<Support>,
    /// Nodal loads (components; several on one DOF add up).
    pub loads: Vec<Load>,
    /// Contact settings, when the model has `[contact]`.
    pub contact: Option<ContactSettings>,
    /// Explicit contact pairs.
    pub explicit_contacts: Vec<ExplicitContact>,
    /// The periodic cell, when the model is one (validated geometry; pairing happens in
    /// [`crate::cell`]).
    pub cell: Option<CellSpec>,
    elements: Vec<Element>,
    node_index: HashMap<u64, usize>,
    contact_specs: (Option<ContactSpec>, Vec<ContactPairSpec>),
}

fn check_material(m: &super::MaterialSpec) -> Result<Material, ModelError> {
    let invalid = |what, value, rule| ModelError::InvalidMaterial {
        material: m.name.clone(),
        what,
        value,
        rule,
    };
    if !(m.young.is_finite() && m.young > 0.0) {
        return Err(invalid("young", m.young, "finite and > 0"));
    }
    let shear = match (m.poisson, m.shear) {
        (Some(nu), None) => {
            if !(nu > -1.0 && nu < 0.5) {
                return Err(invalid("poisson", nu, "−1 < ν < 0.5"));
            }
            m.young / (2.0 * (1.0 + nu))
        }
        (None, Some(g)) => {
            if !(g.is_finite() && g > 0.0) {
                return Err(invalid("shear", g, "finite and > 0"));
            }
            g
        }
        _ => return Err(ModelError::MaterialUnderdetermined(m.name.clone())),
    };
    Ok(Material {
        name: m.name.clone(),
        young: m.young,
        shear,
        poisson: m.poisson,
    })
}

/// Diagonal of the bounding box of `nodes`.
fn bounding_diagonal(nodes: &[Node]) -> f64 {
    let (lo, hi) = nodes
        .iter()
        .fold(([f64::MAX; 3], [f64::MIN; 3]), |(lo, hi), n| {
            (
                [0, 1, 2].map(|k| lo[k].min(n.x[k])),
                [0, 1, 2].map(|k| hi[k].max(n.x[k])),
            )
        });
    (0..3).map(|k| (hi[k] - lo[k]).powi(2)).sum::<f64>().sqrt()
}

/// The largest coordinate (and prescribed displacement) magnitude a model may have (m):
/// squared lengths of elements between such nodes stay finite.
pub const MAX_COORDINATE: f64 = 1e100;

/// The largest load component a model may have (N, N·m): norms of the load vector and the
/// displacements it causes stay finite.
pub const MAX_LOAD: f64 = 1e100;

fn check_cell(c: &super::CellSpec) -> Result<(), ModelError> {
    let bad = |what: &str, v: f64| {
        ModelError::InvalidCell(format!("{what} = {v} must be finite and > 0"))
    };
    for (k, v) in c.size.iter().enumerate() {
        if !(v.is_finite() && *v > 0.0) {
            return Err(bad(["size[0] (L_x)", "size[1] (L_y)"][k], *v));
        }
    }
    if let Some(o) = c.origin {
        if o.iter().any(|v| !v.is_finite()) {
            return Err(ModelError::InvalidCell(format!(
                "origin {o:?} is not finite"
            )));
        }
    }
    for (what, v) in [("thickness", c.thickness), ("tolerance", c.tolerance)] {
        if let Some(v) = v {
            if !(v.is_finite() && v > 0.0) {
                return Err(bad(what, v));
            }
        }
    }
    Ok(())
}

/// What a periodic cell cannot hold: nodal loads (it is driven by the macroscopic strains,
/// and they would be ignored) and fibers as thick as a period (a fiber would overlap its own
/// periodic image).
fn check_cell_contents(c: &super::CellSpec, d: &ModelDescription) -> Result<(), ModelError> {
    if let Some(l) = d.loads.first() {
        return Err(ModelError::InvalidCell(format!(
            "[[loads]] at node {} (and {} more): a periodic cell is loaded by macroscopic \
             strains (`fibercell curve --strain …`) and its effective stiffness is its response \
             to them (`homogenize`); nodal loads would be ignored, so remove them",
            l.node,
            d.loads.len() - 1
        )));
    }
    let period = c.size[0].min(c.size[1]);
    if let Some(f) = d.fibers.iter().find(|f| 2.0 * f.radius >= period) {
        return Err(ModelError::InvalidCell(format!(
            "fiber {} has the diameter {} m, not below the cell's shorter period {period} m: it \
             would overlap its own periodic image (radius in m, e.g. 1e-5 for 10 µm)",
            f.id,
            2.0 * f.radius
        )));
    }
    Ok(())
}

impl Model {
    /// Validates a description and builds the model. Every failure names the item.
    pub fn from_description(d: &ModelDescription) -> Result<Model, ModelError> {
        if d.nodes.is_empty() {
            return Err(ModelError::Empty("nodes"));
        }
        if d.fibers.is_empty() {
            return Err(ModelError::Empty("fibers"));
        }
        let mut materials = Vec::with_capacity(d.materials.len());
        let mut material_index = HashMap::new();
        for m in &d.materials {
            if material_index
                .insert(m.name.clone(), materials.len())
                .is_some()
            {
                return Err(ModelError::DuplicateMaterial(m.name.clone()));
            }
            materials.push(check_material(m)?);
        }
        let mut nodes = Vec::with_capacity(d.nodes.len());
        let mut node_index = HashMap::with_capacity(d.nodes.len());
        for n in &d.nodes {
            if node_index.insert(n.id, nodes.len()).is_some() {
                return Err(ModelError::DuplicateNode(n.id));
            }
            if n.x.iter().any(|c| !(c.abs() <= MAX_COORDINATE)) {
                return Err(ModelError::NonFiniteCoordinate {
                    node: n.id,
                    coordinate: n.x,
                });
            }
            nodes.push(Node { id: n.id, x: n.x });
        }
        let lookup = |id: u64, referrer: &dyn Fn() -> String| {
            node_index
                .get(&id)
                .copied()
                .ok_or_else(|| ModelError::UnknownNode {
                    node: id,
                    referrer: referrer(),
                })
        };
        // Length scale for "zero length": the bounding box diagonal.
        let min_length = 1e-12 * bounding_diagonal(&nodes).max(f64::MIN_POSITIVE);

        let mut fibers = Vec::with_capacity(d.fibers.len());
        let mut fiber_ids = HashMap::new();
        let mut elements = Vec::new();
        let mut element_owner: HashMap<(usize, usize), u64> = HashMap::new();
        let mut used = vec![false; nodes.len()];
        for f in &d.fibers {
            if fiber_ids.insert(f.id, fibers.len()).is_some() {
                return Err(ModelError::DuplicateFiber(f.id));
            }
            if f.nodes.len() < 2 {
                return Err(ModelError::FiberTooShort(f.id));
            }
            if !(f.radius.is_finite() && f.radius > 0.0) {
                return Err(ModelError::InvalidRadius {
                    fiber: f.id,
                    radius: f.radius,
                });
            }
            let material =
                *material_index
                    .get(&f.material)
                    .ok_or_else(|| ModelError::UnknownMaterial {
                        fiber: f.id,
                        material: f.material.clone(),
                    })?;
            let idx = f
                .nodes
                .iter()
                .map(|&id| lookup(id, &|| format!("fiber {}", f.id)))
                .collect::<Result<Vec<_>, _>>()?;
            for w in idx.windows(2) {
                let (a, b) = (w[0], w[1]);
                let l2: f64 = (0..3)
                    .map(|k| (nodes[b].x[k] - nodes[a].x[k]).powi(2))
                    .sum();
                if l2.sqrt() <= min_length {
                    return Err(ModelError::ZeroLengthElement {
                        fiber: f.id,
                        node_a: nodes[a].id,
                        node_b: nodes[b].id,
                    });
                }
                if let Some(&other) = element_owner.get(&(a.min(b), a.max(b))) {
                    return Err(ModelError::DuplicateElement {
                        node_a: nodes[a].id,
                        node_b: nodes[b].id,
                        fiber_a: other,
                        fiber_b: f.id,
                    });
                }
                element_owner.insert((a.min(b), a.max(b)), f.id);
                elements.push(Element {
                    fiber: fibers.len(),
                    nodes: [a, b],
                });
                used[a] = true;
                used[b] = true;
            }
            let section = Section { radius: f.radius };
            let young = materials[material].young;
            if !(young * section.second_moment()).is_finite() {
                return Err(ModelError::InvalidRadius {
                    fiber: f.id,
                    radius: f.radius,
                });
            }
            fibers.push(Fiber {
                id: f.id,
                nodes: idx,
                section,
                material,
            });
        }
        if let Some(i) = used.iter().position(|u| !u) {
            return Err(ModelError::UnusedNode(nodes[i].id));
        }
        let mut supports: Vec<Support> = Vec::new();
        let mut prescribed: HashMap<(usize, Dof), f64> = HashMap::new();
        for s in &d.supports {
            let node = lookup(s.node, &|| "a support".to_string())?;
            if !(s.value.abs() <= MAX_COORDINATE) {
                return Err(ModelError::NonFiniteValue {
                    node: s.node,
                    what: "prescribed value",
                });
            }
            for set in &s.dofs {
                for &dof in set.dofs() {
                    match prescribed.insert((node, dof), s.value) {
                        Some(v) if v != s.value => {
                            return Err(ModelError::ConflictingSupport { node: s.node, dof })
                        }
                        Some(_) => {}
                        None => supports.push(Support {
                            node,
                            dof,
                            value: s.value,
                        }),
                    }
                }
            }
        }
        let mut loads = Vec::new();
        for l in &d.loads {
            let node = lookup(l.node, &|| "a load".to_string())?;
            if l.force
                .iter()
                .chain(&l.moment)
                .any(|v| !(v.abs() <= MAX_LOAD))
            {
                return Err(ModelError::NonFiniteValue {
                    node: l.node,
                    what: "load",
                });
            }
            for (k, &v) in l.force.iter().chain(&l.moment).enumerate() {
                if v != 0.0 {
                    loads.push(Load {
                        node,
                        dof: Dof::ALL[k],
                        value: v,
                    });
                }
            }
        }
        let max_radius = fibers.iter().map(|f| f.section.radius).fold(0.0, f64::max);
        let contact = d
            .contact
            .as_ref()
            .map(|c| check_settings(c, max_radius))
            .transpose()?;
        let first_element: Vec<usize> = {
            let mut v = Vec::with_capacity(fibers.len());
            let mut count = 0;
            for f in &fibers {
                v.push(count);
                count += f.nodes.len() - 1;
            }
            v
        };
        let side = |s: &SideSpec| -> Result<ContactSide, String> {
            match *s {
                SideSpec::Node { node } => node_index
                    .get(&node)
                    .map(|&i| ContactSide::Node(i))
                    .ok_or(format!("unknown node {node}")),
                SideSpec::Point { fiber, segment, xi } => {
                    let f = *fiber_ids
                        .get(&fiber)
                        .ok_or(format!("unknown fiber {fiber}"))?;
                    if segment >= fibers[f].nodes.len().saturating_sub(1) {
                        return Err(format!(
                            "fiber {fiber} has no segment {segment} (it has {})",
                            fibers[f].nodes.len() - 1
                        ));
                    }
                    if !(0.0..=1.0).contains(&xi) {
                        return Err(format!("xi = {xi} is outside [0, 1]"));
                    }
                    Ok(ContactSide::Point {
                        element: first_element[f] + segment,
                        xi,
                    })
                }
            }
        };
        let explicit_contacts = d
            .contacts
            .iter()
            .enumerate()
            .map(|(k, c)| check_pair(k, c, &side))
            .collect::<Result<Vec<_>, _>>()?;
        if !explicit_contacts.is_empty() && contact.is_none() {
            return Err(ModelError::InvalidContact {
                item: "[[contacts]]".into(),
                message:
                    "explicit contact pairs need a [contact] section (friction law, penalties)"
                        .into(),
            });
        }
        if let Some(c) = &d.cell {
            check_cell(c)?;
            check_cell_contents(c, d)?;
        }
        Ok(Model {
            name: d.name.clone(),
            nodes,
            materials,
            fibers,
            supports,
            loads,
            contact,
            explicit_contacts,
            cell: d.cell.clone(),
            elements,
            node_index,
            contact_specs: (d.contact.clone(), d.contacts.clone()),
        })
    }

    /// All frame elements, fiber after fiber.
    pub fn elements(&self) -> &[Element] {
        &self.elements
    }

    /// Index of the node with this id.
    pub fn node_index(&self, id: u64) -> Option<usize> {
        self.node_index.get(&id).copied()
    }

    /// Ids of the fibers passing through node index `node`.
    pub fn fibers_at_node(&self, node: usize) -> Vec<u64> {
        let mut ids: Vec<u64> = self
            .elements
            .iter()
            .filter(|e| e.nodes.contains(&node))
            .map(|e| self.fibers[e.fiber].id)
            .collect();
        ids.sort_unstable();
        ids.dedup();
        ids
    }

    /// Back to the file schema (for writing TOML/JSON).
    pub fn to_description(&self) -> ModelDescription {
        use super::{DofSet, FiberSpec, LoadSpec, MaterialSpec, NodeSpec, SupportSpec};
        let set = |d: Dof| match d {
            Dof::Ux => DofSet::Ux,
            Dof::Uy => DofSet::Uy,
            Dof::Uz => DofSet::Uz,
            Dof::Rx => DofSet::Rx,
            Dof::Ry => DofSet::Ry,
            Dof::Rz => DofSet::Rz,
        };
        let mut loads: Vec<LoadSpec> = Vec::new();
        for l in &self.loads {
            let node = self.nodes[l.node].id;
            let idx = match loads.iter().position(|x| x.node == node) {
                Some(i) => i,
                None => {
                    loads.push(LoadSpec {
                        node,
                        force: [0.0; 3],
                        moment: [0.0; 3],
                    });
                    loads.len() - 1
                }
            };
            let k = l.dof.index();
            if k < 3 {
                loads[idx].force[k] += l.value;
            } else {
                loads[idx].moment[k - 3] += l.value;
            }
        }
        ModelDescription {
            name: self.name.clone(),
            materials: self
                .materials
                .iter()
                .map(|m| MaterialSpec {
                    name: m.name.clone(),
                    young: m.young,
                    poisson: m.poisson,
                    shear: if m.poisson.is_some() {
                        None
                    } else {
                        Some(m.shear)
                    },
                })
                .collect(),
            nodes: self
                .nodes
                .iter()
                .map(|n| NodeSpec { id: n.id, x: n.x })
                .collect(),
            fibers: self
                .fibers
                .iter()
                .map(|f| FiberSpec {
                    id: f.id,
                    nodes: f.nodes.iter().map(|&i| self.nodes[i].id).collect(),
                    radius: f.section.radius,
                    material: self.materials[f.material].name.clone(),
                })
                .collect(),
            supports: self
                .supports
                .iter()
                .map(|s| SupportSpec {
                    node: self.nodes[s.node].id,
                    dofs: vec![set(s.dof)],
                    value: s.value,
                })
                .collect(),
            loads,
            contact: self.contact_specs.0.clone(),
            contacts: self.contact_specs.1.clone(),
            cell: self.cell.clone(),
        }
    }

    /// Diagonal of the bounding box of the nodes (m): the model's length scale.
    pub fn size(&self) -> f64 {
        bounding_diagonal(&self.nodes)
    }

    /// Whether the model has contact (settings present).
    pub fn has_contact(&self) -> bool {
        self.contact.is_some()
    }
}
