//! Pairing of boundary nodes across opposite faces of the periodic cell.

pub use crate::error::CellError;
use crate::model::Model;
use std::collections::HashMap;

/// Box, mid-surface, thickness and pairing tolerance of a cell.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CellGeometry {
    /// Lower-left corner (x₀, y₀).
    pub origin: [f64; 2],
    /// Periods (L_x, L_y).
    pub size: [f64; 2],
    /// z of the mid-surface (the reference of curvatures): middle of the fibers' z extent.
    pub z_mid: f64,
    /// Thickness h (m).
    pub thickness: f64,
    /// Pairing tolerance (m).
    pub tolerance: f64,
}

impl CellGeometry {
    /// Cell area L_x L_y.
    pub fn area(&self) -> f64 {
        self.size[0] * self.size[1]
    }

    /// Position relative to the origin and the mid-surface.
    pub fn relative(&self, x: &[f64; 3]) -> [f64; 3] {
        [
            x[0] - self.origin[0],
            x[1] - self.origin[1],
            x[2] - self.z_mid,
        ]
    }
}

/// The periodic structure of a cell: for every node, `None` if it carries its own DOFs, or its
/// master node and the number of periods (i, j) it is shifted by (u_slave = u_master + macro
/// jump).
#[derive(Clone, Debug, PartialEq)]
pub struct Periodicity {
    /// Geometry.
    pub geometry: CellGeometry,
    /// Master and shift of every node.
    pub master: Vec<Option<(usize, [i32; 2])>>,
}

impl Periodicity {
    /// Number of slave nodes.
    pub fn n_slaves(&self) -> usize {
        self.master.iter().filter(|m| m.is_some()).count()
    }
}

/// The independent node of node `n`: its master in a cell, itself outside one.
pub(crate) fn independent_node(cell: Option<&Periodicity>, n: usize) -> usize {
    cell.and_then(|p| p.master[n]).map_or(n, |(m, _)| m)
}

/// Pairs every node on the faces x = x₀ + L_x and y = y₀ + L_y with a node on the opposite
/// face at the same other coordinates; fails naming unpaired, ambiguous or outside nodes.
pub fn pair_boundary_nodes(model: &Model) -> Result<Periodicity, CellError> {
    let spec = model.cell.as_ref().ok_or(CellError::NotACell)?;
    let n = model.nodes.len();
    let min = |k: usize| {
        model
            .nodes
            .iter()
            .map(|p| p.x[k])
            .fold(f64::INFINITY, f64::min)
    };
    let max = |k: usize| {
        model
            .nodes
            .iter()
            .map(|p| p.x[k])
            .fold(f64::NEG_INFINITY, f64::max)
    };
    let origin = spec.origin.unwrap_or([min(0), min(1)]);
    let tol = spec
        .tolerance
        .unwrap_or(1e-6 * spec.size[0].min(spec.size[1]));
    let r_max = model
        .fibers
        .iter()
        .map(|f| f.section.radius)
        .fold(0.0, f64::max);
    let (zlo, zhi) = (min(2), max(2));
    let geometry = CellGeometry {
        origin,
        size: spec.size,
        z_mid: 0.5 * (zlo + zhi),
        thickness: spec.thickness.unwrap_or(zhi - zlo + 2.0 * r_max),
        tolerance: tol,
    };
    let hi = [origin[0] + spec.size[0], origin[1] + spec.size[1]];
    let outside: Vec<u64> = model
        .nodes
        .iter()
        .filter(|p| (0..2).any(|k| p.x[k] < origin[k] - tol || p.x[k] > hi[k] + tol))
        .map(|p| p.id)
        .collect();
    if !outside.is_empty() {
        return Err(CellError::Outside {
            nodes: outside,
            x0: origin[0],
            x1: hi[0],
            y0: origin[1],
            y1: hi[1],
        });
    }
    // partner[axis][node] = node on the low face paired with this high-face node.
    let mut partner: [Vec<Option<usize>>; 2] = [vec![None; n], vec![None; n]];
    for axis in 0..2 {
        let other = 1 - axis;
        let on = |i: usize, v: f64| (model.nodes[i].x[axis] - v).abs() <= tol;
        let low: Vec<usize> = (0..n).filter(|&i| on(i, origin[axis])).collect();
        let high: Vec<usize> = (0..n).filter(|&i| on(i, hi[axis])).collect();
        let cell = 2.0 * tol;
        let key = |i: usize| {
            let p = &model.nodes[i].x;
            (
                (p[other] / cell).floor() as i64,
                (p[2] / cell).floor() as i64,
            )
        };
        let mut grid: HashMap<(i64, i64), Vec<usize>> = HashMap::new();
        for &i in &low {
            grid.entry(key(i)).or_default().push(i);
        }
        let mut used = vec![false; n];
        let mut unpaired_high = Vec::new();
        for &h in &high {
            let (a, b) = key(h);
            let p = &model.nodes[h].x;
            let mut found = Vec::new();
            for da in -1..=1 {
                for db in -1..=1 {
                    for &l in grid.get(&(a + da, b + db)).map(|v| &v[..]).unwrap_or(&[]) {
                        let q = &model.nodes[l].x;
                        if (p[other] - q[other]).abs() <= tol && (p[2] - q[2]).abs() <= tol {
                            found.push(l);
                        }
                    }
                }
            }
            match found.len() {
                0 => unpaired_high.push(model.nodes[h].id),
                1 => {
                    partner[axis][h] = Some(found[0]);
                    used[found[0]] = true;
                }
                _ => {
                    return Err(CellError::Ambiguous {
                        node: model.nodes[h].id,
                        candidates: found.iter().map(|&l| model.nodes[l].id).collect(),
                    })
                }
            }
        }
        let names = [["x = x0", "x = x0 + Lx"], ["y = y0", "y = y0 + Ly"]][axis];
        if !unpaired_high.is_empty() {
            return Err(CellError::Unpaired {
                nodes: unpaired_high,
                face: names[1].into(),
            });
        }
        let unpaired_low: Vec<u64> = low
            .iter()
            .filter(|&&l| !used[l])
            .map(|&l| model.nodes[l].id)
            .collect();
        if !unpaired_low.is_empty() {
            return Err(CellError::Unpaired {
                nodes: unpaired_low,
                face: names[0].into(),
            });
        }
    }
    // Follow high → low links (at most one per axis) to the independent master.
    let master = (0..n)
        .map(|i| {
            let (mut m, mut shift) = (i, [0i32; 2]);
            for _ in 0..2 {
                if let Some(p) = partner[0][m] {
                    m = p;
                    shift[0] += 1;
                } else if let Some(p) = partner[1][m] {
                    m = p;
                    shift[1] += 1;
                }
            }
            (m != i).then_some((m, shift))
        })
        .collect();
    Ok(Periodicity { geometry, master })
}

/// The independent node nearest the cell centre: its translations are fixed to remove the rigid
/// translations, the only rigid motions periodicity leaves.
pub fn anchor_node(model: &Model, p: &Periodicity) -> Result<usize, CellError> {
    let g = &p.geometry;
    let centre = [g.origin[0] + 0.5 * g.size[0], g.origin[1] + 0.5 * g.size[1]];
    let d = |i: usize| {
        (model.nodes[i].x[0] - centre[0]).powi(2) + (model.nodes[i].x[1] - centre[1]).powi(2)
    };
    (0..model.nodes.len())
        .filter(|&i| p.master[i].is_none())
        .min_by(|&a, &b| d(a).total_cmp(&d(b)))
        .ok_or(CellError::NotACell)
}
