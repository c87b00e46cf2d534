//! Abaqus `.inp` import of beam models.
//!
//! Supported: `*HEADING`, `*NODE`, `*ELEMENT, TYPE=B31|B33` (two-node beams, read as
//! Euler–Bernoulli frame elements: B31's shear flexibility is neglected, which for slender fibers
//! changes nothing measurable), `*NSET`/`*ELSET` (with `GENERATE`), `*BEAM SECTION,
//! SECTION=CIRC` (radius on the data line, optional n1 direction line — irrelevant for a
//! circular section), `*MATERIAL`/`*ELASTIC` (E, ν), `*STEP`/`*STATIC`/`*END STEP`,
//! `*BOUNDARY` (node or set, first DOF, last DOF, value; or ENCASTRE/PINNED), `*CLOAD` (node or
//! set, DOF, value), `**` comments, case-insensitive keywords. Any other keyword is an error
//! naming it and its line. Elements of one section are chained into fibers (polylines), split
//! where a node joins other than two of them.

use super::InputError;
use crate::model::{
    DofSet, FiberSpec, LoadSpec, MaterialSpec, ModelDescription, NodeSpec, SupportSpec,
};
use std::collections::{BTreeMap, HashMap};

struct Section {
    elset: String,
    material: String,
    radius: Option<f64>,
    line: usize,
    /// The n1 direction line and where it is.
    n1: Option<([f64; 3], usize)>,
}

#[derive(Default)]
struct Reader {
    path: String,
    name: Option<String>,
    nodes: Vec<NodeSpec>,
    elements: Vec<(u64, u64, u64)>,
    element_line: HashMap<u64, usize>,
    nsets: HashMap<String, Vec<u64>>,
    elsets: HashMap<String, Vec<u64>>,
    sections: Vec<Section>,
    materials: Vec<MaterialSpec>,
    supports: Vec<SupportSpec>,
    loads: Vec<LoadSpec>,
    steps: usize,
    /// `*EQUATION`s: (line, terms (node or set, DOF, coefficient)).
    equations: Vec<super::abaqus_cell::Equation>,
    /// The equation being read: its number of terms and line.
    equation: Option<(usize, usize)>,
    /// `** fibercell-…:` settings.
    contact: Option<crate::model::ContactSpec>,
    contacts: Vec<crate::model::ContactPairSpec>,
    cell: Option<crate::model::CellSpec>,
    /// Exact coordinates of nodes whose `*NODE` line is rounded to the 20-character field.
    exact_nodes: Vec<ExactNode>,
    /// Members of all `GENERATE` sets so far (see [`MAX_GENERATED_MEMBERS`]).
    generated: usize,
}

/// A `** fibercell-node:` comment: the exact coordinates of a node the exporter rounded.
#[derive(serde::Deserialize)]
struct ExactNode {
    id: u64,
    x: [f64; 3],
}

impl Reader {
    /// The exact coordinates of the nodes whose lines still hold what the exporter wrote for
    /// them (a line edited since keeps its own values).
    fn restore_exact_nodes(&mut self) {
        let exact: HashMap<u64, [f64; 3]> = self.exact_nodes.iter().map(|n| (n.id, n.x)).collect();
        for node in &mut self.nodes {
            let Some(x) = exact.get(&node.id) else {
                continue;
            };
            let written = x.map(|v| super::inp_number(v).parse::<f64>());
            if written
                .iter()
                .zip(&node.x)
                .all(|(w, v)| w.as_ref() == Ok(v))
            {
                node.x = *x;
            }
        }
    }
}

/// The most members all `GENERATE` sets of one file may hold together (80 MB of ids): 700
/// bytes of twelve sets of 10⁸ took 10 GB and 34 s before the cap was on the total.
pub const MAX_GENERATED_MEMBERS: usize = 10_000_000;

#[derive(Clone, Copy, PartialEq)]
enum Block {
    None,
    Heading,
    Node,
    Element,
    Nset {
        generate: bool,
    },
    Elset {
        generate: bool,
    },
    BeamSection,
    BeamSectionDirection,
    Elastic,
    Static,
    Boundary,
    Cload,
    Equation,
    /// The variables of an output request (ignored).
    Output,
}

fn params(parts: &[&str]) -> HashMap<String, String> {
    parts
        .iter()
        .filter_map(|p| {
            let mut kv = p.splitn(2, '=');
            let k = kv.next()?.trim().to_ascii_uppercase();
            let v = kv.next().unwrap_or("").trim().to_string();
            (!k.is_empty()).then_some((k, v))
        })
        .collect()
}

impl Reader {
    fn err(&self, line: usize, message: impl Into<String>) -> InputError {
        InputError::Syntax {
            path: self.path.clone(),
            line,
            column: 1,
            message: message.into(),
        }
    }

    fn num(&self, line: usize, s: &str, what: &str) -> Result<f64, InputError> {
        let v: f64 = s
            .trim()
            .replace(['d', 'D'], "e")
            .parse()
            .map_err(|_| self.err(line, format!("{what}: \"{}\" is not a number", s.trim())))?;
        Ok(v)
    }

    fn id(&self, line: usize, s: &str, what: &str) -> Result<u64, InputError> {
        s.trim().parse().map_err(|_| {
            self.err(
                line,
                format!("{what}: \"{}\" is not a positive integer id", s.trim()),
            )
        })
    }

    fn dof(&self, line: usize, s: &str) -> Result<DofSet, InputError> {
        let k = self.id(line, s, "DOF")?;
        Ok(match k {
            1 => DofSet::Ux,
            2 => DofSet::Uy,
            3 => DofSet::Uz,
            4 => DofSet::Rx,
            5 => DofSet::Ry,
            6 => DofSet::Rz,
            _ => return Err(self.err(line, format!("DOF {k} is not in 1..6"))),
        })
    }

    /// A node id or the name of a node set.
    fn node_targets(&self, line: usize, s: &str) -> Result<Vec<u64>, InputError> {
        let s = s.trim();
        if let Ok(id) = s.parse::<u64>() {
            return Ok(vec![id]);
        }
        self.nsets
            .get(&s.to_ascii_uppercase())
            .cloned()
            .ok_or_else(|| self.err(line, format!("unknown node or node set \"{s}\"")))
    }

    fn set_members(
        &mut self,
        line: usize,
        fields: &[&str],
        generate: bool,
    ) -> Result<Vec<u64>, InputError> {
        let fields: Vec<&str> = fields
            .iter()
            .copied()
            .filter(|f| !f.trim().is_empty())
            .collect();
        if generate {
            if fields.len() < 2 || fields.len() > 3 {
                return Err(self.err(line, "GENERATE needs first, last[, increment]"));
            }
            let a = self.id(line, fields[0], "first")?;
            let b = self.id(line, fields[1], "last")?;
            let inc = if fields.len() == 3 {
                self.id(line, fields[2], "increment")?
            } else {
                1
            };
            if inc == 0 || b < a {
                return Err(self.err(line, "GENERATE needs first ≤ last and a positive increment"));
            }
            let count = usize::try_from((b - a) / inc).map_or(usize::MAX, |n| n.saturating_add(1));
            self.generated = self.generated.saturating_add(count);
            if self.generated > MAX_GENERATED_MEMBERS {
                return Err(self.err(
                    line,
                    format!(
                        "GENERATE sets of more than {MAX_GENERATED_MEMBERS} members in all \
                         (this one: {count}); list the members or generate smaller ranges"
                    ),
                ));
            }
            return Ok((a..=b).step_by(inc as usize).collect());
        }
        fields
            .iter()
            .map(|f| self.id(line, f, "set member"))
            .collect()
    }

    fn data_line(
        &mut self,
        block: Block,
        line: usize,
        fields: &[&str],
        ctx: &mut Context,
    ) -> Result<Block, InputError> {
        let need = |n: usize, what: &str| -> Result<(), InputError> {
            if fields.iter().filter(|f| !f.trim().is_empty()).count() < n {
                Err(self.err(line, format!("{what} needs at least {n} values")))
            } else {
                Ok(())
            }
        };
        match block {
            Block::None => return Err(self.err(line, "data line outside any keyword block")),
            Block::Heading => {
                if self.name.is_none() {
                    self.name = Some(fields.join(",").trim().to_string());
                }
            }
            Block::Node => {
                need(3, "*NODE")?;
                let id = self.id(line, fields[0], "node id")?;
                let mut x = [0.0; 3];
                for (xk, f) in x.iter_mut().zip(&fields[1..]) {
                    if !f.trim().is_empty() {
                        *xk = self.num(line, f, "coordinate")?;
                    }
                }
                self.nodes.push(NodeSpec { id, x });
                if let Some(set) = &ctx.nset {
                    self.nsets.entry(set.clone()).or_default().push(id);
                }
            }
            Block::Element => {
                let f: Vec<&str> = fields
                    .iter()
                    .copied()
                    .filter(|f| !f.trim().is_empty())
                    .collect();
                if f.len() != 3 {
                    return Err(self.err(
                        line,
                        format!(
                            "two-node beam element needs id, node, node; found {} values",
                            f.len()
                        ),
                    ));
                }
                let id = self.id(line, f[0], "element id")?;
                let a = self.id(line, f[1], "node")?;
                let b = self.id(line, f[2], "node")?;
                if let Some(first) = self.element_line.insert(id, line) {
                    return Err(self.err(
                        line,
                        format!("element {id} already defined on line {first}"),
                    ));
                }
                self.elements.push((id, a, b));
                if let Some(set) = &ctx.elset {
                    self.elsets.entry(set.clone()).or_default().push(id);
                }
            }
            Block::Nset { generate } => {
                let m = self.set_members(line, fields, generate)?;
                if let Some(set) = &ctx.nset {
                    self.nsets.entry(set.clone()).or_default().extend(m);
                }
            }
            Block::Elset { generate } => {
                let m = self.set_members(line, fields, generate)?;
                if let Some(set) = &ctx.elset {
                    self.elsets.entry(set.clone()).or_default().extend(m);
                }
            }
            Block::BeamSection => {
                need(1, "*BEAM SECTION, SECTION=CIRC")?;
                let r = self.num(line, fields[0], "radius")?;
                if let Some(s) = self.sections.last_mut() {
                    s.radius = Some(r);
                }
                return Ok(Block::BeamSectionDirection);
            }
            Block::BeamSectionDirection => {
                // n1 direction: checked (here, and against the elements once they are known),
                // then irrelevant for a circular section.
                need(3, "beam section direction")?;
                let mut n1 = [0.0; 3];
                for (v, f) in n1.iter_mut().zip(&fields[..3]) {
                    *v = self.num(line, f, "direction")?;
                }
                if !n1.iter().all(|v| v.is_finite()) || n1.iter().all(|&v| v == 0.0) {
                    return Err(self.err(
                        line,
                        format!("beam section direction n1 = {n1:?} must be finite and nonzero"),
                    ));
                }
                if let Some(s) = self.sections.last_mut() {
                    s.n1 = Some((n1, line));
                }
                return Ok(Block::None);
            }
            Block::Elastic => {
                need(2, "*ELASTIC")?;
                let e = self.num(line, fields[0], "E")?;
                let nu = self.num(line, fields[1], "ν")?;
                let name = ctx
                    .material
                    .clone()
                    .ok_or_else(|| self.err(line, "*ELASTIC outside a *MATERIAL"))?;
                self.materials.push(MaterialSpec {
                    name,
                    young: e,
                    poisson: Some(nu),
                    shear: None,
                });
                return Ok(Block::None);
            }
            Block::Static | Block::Output => {}
            Block::Boundary => {
                need(2, "*BOUNDARY")?;
                let targets = self.node_targets(line, fields[0])?;
                let second = fields[1].trim().to_ascii_uppercase();
                let (dofs, value) = match second.as_str() {
                    "ENCASTRE" => (vec![DofSet::All], 0.0),
                    "PINNED" => (vec![DofSet::Translations], 0.0),
                    _ => {
                        let first = self.dof(line, fields[1])?;
                        let last = match fields.get(2).filter(|f| !f.trim().is_empty()) {
                            Some(f) => self.dof(line, f)?,
                            None => first,
                        };
                        let (a, b) = (first.dofs()[0].index(), last.dofs()[0].index());
                        if b < a {
                            return Err(self.err(line, "last DOF before first DOF"));
                        }
                        let value = match fields.get(3).filter(|f| !f.trim().is_empty()) {
                            Some(f) => self.num(line, f, "prescribed value")?,
                            None => 0.0,
                        };
                        let sets = [
                            DofSet::Ux,
                            DofSet::Uy,
                            DofSet::Uz,
                            DofSet::Rx,
                            DofSet::Ry,
                            DofSet::Rz,
                        ];
                        (sets[a..=b].to_vec(), value)
                    }
                };
                for node in targets {
                    self.supports.push(SupportSpec {
                        node,
                        dofs: dofs.clone(),
                        value,
                    });
                }
            }
            Block::Equation => self.equation_line(line, fields)?,
            Block::Cload => {
                need(3, "*CLOAD")?;
                let targets = self.node_targets(line, fields[0])?;
                let k = self.dof(line, fields[1])?.dofs()[0].index();
                let v = self.num(line, fields[2], "load")?;
                for node in targets {
                    let mut l = LoadSpec {
                        node,
                        force: [0.0; 3],
                        moment: [0.0; 3],
                    };
                    if k < 3 {
                        l.force[k] = v;
                    } else {
                        l.moment[k - 3] = v;
                    }
                    self.loads.push(l);
                }
            }
        }
        Ok(block)
    }

    /// A data line of `*EQUATION`: the number of terms, then (node or set, DOF, coefficient)
    /// triples, several per line.
    fn equation_line(&mut self, line: usize, fields: &[&str]) -> Result<(), InputError> {
        let fields: Vec<&str> = fields
            .iter()
            .map(|f| f.trim())
            .filter(|f| !f.is_empty())
            .collect();
        match self.equation {
            None => {
                if fields.len() != 1 {
                    return Err(self.err(line, "*EQUATION: expected the number of terms"));
                }
                let n = self.id(line, fields[0], "number of terms")? as usize;
                if !(2..=1000).contains(&n) {
                    return Err(self.err(line, format!("*EQUATION with {n} terms (2 to 1000)")));
                }
                self.equation = Some((n, line));
                self.equations.push((line, Vec::with_capacity(n)));
            }
            Some((n, _)) => {
                if !fields.len().is_multiple_of(3) {
                    return Err(self.err(line, "*EQUATION terms come as node, DOF, coefficient"));
                }
                for t in fields.chunks(3) {
                    let dof = self.dof(line, t[1])?.dofs()[0].index() + 1;
                    let c = self.num(line, t[2], "coefficient")?;
                    if let Some((_, terms)) = self.equations.last_mut() {
                        terms.push((t[0].to_ascii_uppercase(), dof, c));
                    }
                }
                let have = self.equations.last().map_or(0, |e| e.1.len());
                if have > n {
                    return Err(
                        self.err(line, format!("*EQUATION has {have} terms, {n} announced"))
                    );
                }
                if have == n {
                    self.equation = None;
                }
            }
        }
        Ok(())
    }

    fn json_setting<T: serde::de::DeserializeOwned>(
        &self,
        line: usize,
        body: &str,
    ) -> Result<T, InputError> {
        serde_json::from_str(body.trim())
            .map_err(|e| self.err(line, format!("fibercell setting: {e}")))
    }

    /// A `** fibercell-…:` comment: settings with no Abaqus keyword, as JSON.
    fn fibercell_comment(&mut self, line: usize, t: &str) -> Result<(), InputError> {
        use super::abaqus_export::{CELL_COMMENT, CONTACT_COMMENT, NODE_COMMENT, PAIR_COMMENT};
        if let Some(body) = t.strip_prefix(CONTACT_COMMENT) {
            self.contact = Some(self.json_setting(line, body)?);
        } else if let Some(body) = t.strip_prefix(PAIR_COMMENT) {
            let pair = self.json_setting(line, body)?;
            self.contacts.push(pair);
        } else if let Some(body) = t.strip_prefix(CELL_COMMENT) {
            self.cell = Some(self.json_setting(line, body)?);
        } else if let Some(body) = t.strip_prefix(NODE_COMMENT) {
            let exact: ExactNode = self.json_setting(line, body)?;
            self.exact_nodes.push(exact);
        }
        Ok(())
    }

    fn keyword(&mut self, line: usize, text: &str, ctx: &mut Context) -> Result<Block, InputError> {
        if let Some((n, start)) = self.equation.take() {
            return Err(self.err(start, format!("*EQUATION ends before its {n} terms")));
        }
        let parts: Vec<&str> = text[1..].split(',').collect();
        let kw = parts[0].trim().to_ascii_uppercase();
        let p = params(&parts[1..]);
        let unsupported = || InputError::UnsupportedKeyword {
            path: self.path.clone(),
            line,
            keyword: parts[0].trim().to_string(),
        };
        let generate = p.contains_key("GENERATE");
        Ok(match kw.as_str() {
            "HEADING" => Block::Heading,
            "NODE" => {
                ctx.nset = p.get("NSET").map(|s| s.to_ascii_uppercase());
                Block::Node
            }
            "ELEMENT" => {
                let ty = p
                    .get("TYPE")
                    .map(|t| t.to_ascii_uppercase())
                    .unwrap_or_default();
                if ty != "B31" && ty != "B33" {
                    return Err(self.err(
                        line,
                        format!(
                            "element TYPE={ty} is not supported (only B31 and B33 two-node beams)"
                        ),
                    ));
                }
                ctx.elset = p.get("ELSET").map(|s| s.to_ascii_uppercase());
                Block::Element
            }
            "NSET" => {
                ctx.nset = Some(
                    p.get("NSET")
                        .ok_or_else(|| self.err(line, "*NSET needs NSET="))?
                        .to_ascii_uppercase(),
                );
                Block::Nset { generate }
            }
            "ELSET" => {
                ctx.elset = Some(
                    p.get("ELSET")
                        .ok_or_else(|| self.err(line, "*ELSET needs ELSET="))?
                        .to_ascii_uppercase(),
                );
                Block::Elset { generate }
            }
            "BEAM SECTION" => {
                let sec = p
                    .get("SECTION")
                    .map(|s| s.to_ascii_uppercase())
                    .unwrap_or_default();
                if sec != "CIRC" {
                    return Err(self.err(
                        line,
                        format!("*BEAM SECTION, SECTION={sec} is not supported (only CIRC)"),
                    ));
                }
                let elset = p
                    .get("ELSET")
                    .ok_or_else(|| self.err(line, "*BEAM SECTION needs ELSET="))?;
                let material = p
                    .get("MATERIAL")
                    .ok_or_else(|| self.err(line, "*BEAM SECTION needs MATERIAL="))?;
                self.sections.push(Section {
                    elset: elset.to_ascii_uppercase(),
                    material: material.to_ascii_uppercase(),
                    radius: None,
                    line,
                    n1: None,
                });
                Block::BeamSection
            }
            "MATERIAL" => {
                // Names are case-insensitive; the spelling of the definition is kept.
                ctx.material = Some(
                    p.get("NAME")
                        .ok_or_else(|| self.err(line, "*MATERIAL needs NAME="))?
                        .to_string(),
                );
                Block::None
            }
            "ELASTIC" => {
                if let Some(t) = p.get("TYPE") {
                    if !t.eq_ignore_ascii_case("ISOTROPIC") {
                        return Err(self.err(
                            line,
                            format!("*ELASTIC, TYPE={t} is not supported (only ISOTROPIC)"),
                        ));
                    }
                }
                Block::Elastic
            }
            "STEP" => {
                self.steps += 1;
                if self.steps > 1 {
                    return Err(self.err(line, "only one *STEP is supported"));
                }
                Block::None
            }
            "STATIC" => Block::Static,
            "END STEP" => Block::None,
            // Output requests change nothing in the model.
            "NODE PRINT" | "NODE FILE" | "EL PRINT" | "EL FILE" | "NODE OUTPUT"
            | "ELEMENT OUTPUT" => Block::Output,
            "OUTPUT" => Block::None,
            "BOUNDARY" => {
                if p.contains_key("TYPE") || p.contains_key("OP") {
                    return Err(self.err(line, "*BOUNDARY options TYPE= and OP= are not supported"));
                }
                Block::Boundary
            }
            "EQUATION" => {
                self.equation = None;
                Block::Equation
            }
            "CLOAD" => {
                if p.contains_key("OP") {
                    return Err(self.err(line, "*CLOAD, OP= is not supported"));
                }
                Block::Cload
            }
            _ => return Err(unsupported()),
        })
    }
}

#[derive(Default)]
struct Context {
    nset: Option<String>,
    elset: Option<String>,
    material: Option<String>,
}

/// Splits the elements of one section into polylines: chains through nodes that join exactly
/// two of them. Returns node-id lists with the id of each chain's first element.
/// A section's n1 must not be parallel to any of its elements (`elements`: id and nodes),
/// which Abaqus refuses: it then defines no cross-section plane.
fn check_n1(
    coordinates: &HashMap<u64, [f64; 3]>,
    elements: &[(u64, u64, u64)],
    n1: [f64; 3],
) -> Result<(), String> {
    let n = nalgebra::Vector3::from(n1);
    for &(id, a, b) in elements {
        let (Some(xa), Some(xb)) = (coordinates.get(&a), coordinates.get(&b)) else {
            continue; // unknown nodes are reported where the fibers are built
        };
        let axis = nalgebra::Vector3::from(*xb) - nalgebra::Vector3::from(*xa);
        if axis.cross(&n).norm() <= 1e-9 * axis.norm() * n.norm() {
            return Err(format!(
                "beam section direction n1 = {n1:?} is parallel to element {id}: it must \
                 point across the beam (any direction not along it, e.g. a coordinate axis)"
            ));
        }
    }
    Ok(())
}

fn chain(elements: &[(u64, u64, u64)]) -> Vec<(u64, Vec<u64>)> {
    let mut at: BTreeMap<u64, Vec<usize>> = BTreeMap::new();
    for (k, &(_, a, b)) in elements.iter().enumerate() {
        at.entry(a).or_default().push(k);
        at.entry(b).or_default().push(k);
    }
    let mut used = vec![false; elements.len()];
    let mut out = Vec::new();
    let walk = |start_el: usize, start_node: u64, used: &mut Vec<bool>| {
        let mut nodes = vec![start_node];
        let mut el = start_el;
        let mut node = start_node;
        loop {
            used[el] = true;
            let (_, a, b) = elements[el];
            node = if a == node { b } else { a };
            nodes.push(node);
            let next = match at.get(&node) {
                Some(v) if v.len() == 2 => v.iter().copied().find(|&k| !used[k]),
                _ => None,
            };
            match next {
                Some(k) => el = k,
                None => break,
            }
        }
        nodes
    };
    // Open chains start at ends and junctions, in element order; what remains are closed loops.
    for k in 0..elements.len() {
        if used[k] {
            continue;
        }
        let (id, a, b) = elements[k];
        let end = [a, b]
            .into_iter()
            .find(|n| at.get(n).is_some_and(|v| v.len() != 2));
        if let Some(start) = end {
            out.push((id, walk(k, start, &mut used)));
        }
    }
    for k in 0..elements.len() {
        if !used[k] {
            let (id, a, _) = elements[k];
            out.push((id, walk(k, a, &mut used)));
        }
    }
    out
}

/// Parses an Abaqus input file into a model description.
pub fn parse_abaqus(text: &str, path: &str) -> Result<ModelDescription, InputError> {
    let mut r = Reader {
        path: path.to_string(),
        ..Reader::default()
    };
    let mut ctx = Context::default();
    let mut block = Block::None;
    for (k, raw) in text.lines().enumerate() {
        let line = k + 1;
        let t = raw.trim();
        if t.starts_with("** fibercell-") {
            r.fibercell_comment(line, t)?;
            continue;
        }
        if t.is_empty() || t.starts_with("**") {
            continue;
        }
        if t.starts_with('*') {
            block = r.keyword(line, t, &mut ctx)?;
        } else {
            let fields: Vec<&str> = t.trim_end_matches(',').split(',').collect();
            block = r.data_line(block, line, &fields, &mut ctx)?;
        }
    }
    r.restore_exact_nodes();
    let path_err = |line: usize, m: String| InputError::Syntax {
        path: path.into(),
        line,
        column: 1,
        message: m,
    };
    // Sections → fibers.
    let by_id: HashMap<u64, (u64, u64, u64)> = r.elements.iter().map(|e| (e.0, *e)).collect();
    let coordinates: HashMap<u64, [f64; 3]> = r.nodes.iter().map(|n| (n.id, n.x)).collect();
    let mut owner: HashMap<u64, usize> = HashMap::new();
    let mut fibers = Vec::new();
    let materials: HashMap<String, String> = r
        .materials
        .iter()
        .map(|m| (m.name.to_ascii_uppercase(), m.name.clone()))
        .collect();
    for (si, s) in r.sections.iter().enumerate() {
        let radius = s.radius.ok_or_else(|| {
            path_err(
                s.line,
                "*BEAM SECTION has no data line with the radius".into(),
            )
        })?;
        let Some(material) = materials.get(&s.material) else {
            return Err(path_err(
                s.line,
                format!("*BEAM SECTION refers to unknown material {}", s.material),
            ));
        };
        let members = r
            .elsets
            .get(&s.elset)
            .ok_or_else(|| path_err(s.line, format!("unknown element set {}", s.elset)))?;
        let mut els = Vec::with_capacity(members.len());
        for id in members {
            let e = by_id.get(id).ok_or_else(|| {
                path_err(
                    s.line,
                    format!("element set {} contains unknown element {id}", s.elset),
                )
            })?;
            if let Some(prev) = owner.insert(*id, si) {
                if prev != si {
                    return Err(path_err(
                        s.line,
                        format!("element {id} has two beam sections"),
                    ));
                }
                continue;
            }
            els.push(*e);
        }
        if let Some((n1, line)) = s.n1 {
            check_n1(&coordinates, &els, n1).map_err(|m| path_err(line, m))?;
        }
        let chains = chain(&els);
        // A section of its own per fiber (`FIBER-<id>`, as fibercell writes) keeps the fiber id.
        let own_id = s
            .elset
            .strip_prefix("FIBER-")
            .and_then(|n| n.parse::<u64>().ok())
            .filter(|_| chains.len() == 1);
        for (id, nodes) in chains {
            fibers.push(FiberSpec {
                id: own_id.unwrap_or(id),
                nodes,
                radius,
                material: material.clone(),
            });
        }
    }
    if let Some(&(id, _, _)) = r.elements.iter().find(|e| !owner.contains_key(&e.0)) {
        return Err(path_err(
            r.element_line[&id],
            format!("element {id} has no *BEAM SECTION"),
        ));
    }
    if let Some((n, line)) = r.equation {
        return Err(path_err(
            line,
            format!("*EQUATION ends before its {n} terms"),
        ));
    }
    let periodic = super::abaqus_cell::periodic_cell(&r.nodes, &r.nsets, &r.equations, path)?;
    let nodes = match &periodic {
        Some(p) => r
            .nodes
            .into_iter()
            .filter(|n| !p.drivers.contains(&n.id))
            .collect(),
        None => r.nodes,
    };
    Ok(ModelDescription {
        name: r.name,
        materials: r.materials,
        nodes,
        fibers,
        supports: r.supports,
        loads: r.loads,
        contact: r.contact,
        contacts: r.contacts,
        cell: r.cell.or(periodic.map(|p| p.cell)),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn chains_split_at_junctions_and_close_loops() {
        // 1-2-3 and 3-4 and 3-5 (junction at 3), plus a triangle loop 10-11-12.
        let els = [
            (1, 1, 2),
            (2, 2, 3),
            (3, 3, 4),
            (4, 5, 3),
            (5, 10, 11),
            (6, 11, 12),
            (7, 12, 10),
        ];
        let c = chain(&els);
        assert_eq!(c[0], (1, vec![1, 2, 3]));
        assert_eq!(c[1], (3, vec![3, 4]));
        assert_eq!(c[2], (4, vec![5, 3]));
        assert_eq!(c[3], (5, vec![10, 11, 12, 10]));
        assert_eq!(c.len(), 4);
    }
}
