//! Statistics of a fiber network: fiber count, total length, solid volume fraction,
//! orientation tensor, contacts and the mean free segment length between contacts.

use crate::cell::{pair_boundary_nodes, strand_of_fibers, Periodicity};
use crate::contact::ContactSet;
use crate::model::Model;
use crate::Error;
use serde::Serialize;

/// Statistics of a model (a periodic cell, or any network).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct NetworkStats {
    /// Fibers of the model (a fiber cut by the cell faces counts once per piece).
    pub fiber_pieces: usize,
    /// Physical fibers: pieces joined end to end through paired boundary nodes count once.
    pub fibers: usize,
    /// Elements.
    pub elements: usize,
    /// Nodes.
    pub nodes: usize,
    /// Total centerline length (m).
    pub total_length: f64,
    /// Fiber volume Σ π r² l (m³).
    pub fiber_volume: f64,
    /// Cell area L_x L_y (m²), for cells.
    pub cell_area: Option<f64>,
    /// Thickness used for the volume fraction (m): the cell's, else the z extent of the fiber
    /// surfaces.
    pub thickness: f64,
    /// z extent of the fiber surfaces (m).
    pub z_extent: f64,
    /// Solid volume fraction: fiber volume / (area × thickness), for cells.
    pub volume_fraction: Option<f64>,
    /// Length-weighted orientation tensor ⟨t ⊗ t⟩ of the elements: a11, a22, a33, a12, a13, a23.
    pub orientation: [f64; 6],
    /// The in-plane tensor of the plan-view directions, normalized: a11, a22, a12.
    pub orientation_in_plane: [f64; 3],
    /// Contact pairs the search and the explicit pairs give (within the search tolerance).
    pub contact_candidates: usize,
    /// Closed contacts (gap ≤ 0 after the initial-penetration treatment).
    pub contacts: usize,
    /// Initially penetrating pairs and the worst overlap (m).
    pub penetrating: usize,
    /// The worst initial overlap (m).
    pub worst_overlap: f64,
    /// Mean free segment length between contacts, total length / (2 × contacts) (m): every
    /// contact ends a free segment on each of its two fibers.
    pub mean_free_segment: Option<f64>,
    /// Closed contacts per physical fiber, 2 × contacts / fibers.
    pub contacts_per_fiber: f64,
}

/// Computes the statistics of `model`; a cell's boundary must pair (the contact search sees
/// the periodic images).
pub fn network_stats(model: &Model) -> Result<NetworkStats, Error> {
    let periodic = match model.cell {
        Some(_) => Some(pair_boundary_nodes(model)?),
        None => None,
    };
    let mut total_length = 0.0;
    let mut volume = 0.0;
    let mut a = [0.0; 6];
    let mut plan = [0.0; 3];
    let mut plan_weight = 0.0;
    let (mut zmin, mut zmax) = (f64::INFINITY, f64::NEG_INFINITY);
    for el in model.elements() {
        let f = &model.fibers[el.fiber];
        let [p, q] = el.nodes.map(|n| model.nodes[n].x);
        let d = [q[0] - p[0], q[1] - p[1], q[2] - p[2]];
        let l = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
        total_length += l;
        volume += f.section.area() * l;
        if l > 0.0 {
            let t = d.map(|v| v / l);
            for (k, (i, j)) in [(0, 0), (1, 1), (2, 2), (0, 1), (0, 2), (1, 2)]
                .into_iter()
                .enumerate()
            {
                a[k] += l * t[i] * t[j];
            }
            let lp = (d[0] * d[0] + d[1] * d[1]).sqrt();
            if lp > 0.0 {
                plan[0] += d[0] * d[0] / lp;
                plan[1] += d[1] * d[1] / lp;
                plan[2] += d[0] * d[1] / lp;
                plan_weight += lp;
            }
        }
        let r = f.section.radius;
        zmin = zmin.min(p[2].min(q[2]) - r);
        zmax = zmax.max(p[2].max(q[2]) + r);
    }
    if total_length > 0.0 {
        a.iter_mut().for_each(|v| *v /= total_length);
    }
    if plan_weight > 0.0 {
        plan.iter_mut().for_each(|v| *v /= plan_weight);
    }
    let z_extent = if zmax > zmin { zmax - zmin } else { 0.0 };
    let cell_area = periodic.as_ref().map(|p| p.geometry.area());
    let thickness = periodic.as_ref().map_or(z_extent, |p| p.geometry.thickness);
    let set = ContactSet::build_with(model, periodic.as_ref())?;
    let contacts = set.pairs.iter().filter(|p| p.gap <= 0.0).count();
    let fibers = physical_fibers(model, periodic.as_ref());
    Ok(NetworkStats {
        fiber_pieces: model.fibers.len(),
        fibers,
        elements: model.elements().len(),
        nodes: model.nodes.len(),
        total_length,
        fiber_volume: volume,
        cell_area,
        thickness,
        z_extent,
        volume_fraction: cell_area
            .filter(|_| thickness > 0.0)
            .map(|area| volume / (area * thickness)),
        orientation: a,
        orientation_in_plane: plan,
        contact_candidates: set.pairs.len(),
        contacts,
        penetrating: set.penetration.count,
        worst_overlap: set.penetration.worst_overlap,
        mean_free_segment: (contacts > 0).then(|| total_length / (2.0 * contacts as f64)),
        contacts_per_fiber: if fibers > 0 {
            2.0 * contacts as f64 / fibers as f64
        } else {
            0.0
        },
    })
}

/// Length-weighted histogram of the plan-view fiber angle θ ∈ [0, π) (axial: θ and θ + π are
/// one direction) in `bins` equal bins; the fractions sum to 1 (all zero without plan length).
pub fn orientation_histogram(model: &Model, bins: usize) -> Vec<f64> {
    let bins = bins.max(1);
    let mut h = vec![0.0; bins];
    for el in model.elements() {
        let [p, q] = el.nodes.map(|n| model.nodes[n].x);
        let (dx, dy) = (q[0] - p[0], q[1] - p[1]);
        let l = (dx * dx + dy * dy).sqrt();
        if l > 0.0 {
            let theta = dy.atan2(dx).rem_euclid(std::f64::consts::PI);
            let k = ((theta / std::f64::consts::PI * bins as f64) as usize).min(bins - 1);
            h[k] += l;
        }
    }
    let total: f64 = h.iter().sum();
    if total > 0.0 {
        h.iter_mut().for_each(|v| *v /= total);
    }
    h
}

/// Physical fibers: pieces that continue one another end to end (through paired boundary
/// nodes, or at a node only they share) count once — as a chain, or as a ring for a yarn that
/// runs around the cell.
fn physical_fibers(model: &Model, periodic: Option<&Periodicity>) -> usize {
    let strands = strand_of_fibers(model, periodic);
    (0..strands.len()).filter(|&f| strands[f] == f).count()
}

impl NetworkStats {
    /// A few lines for a terminal.
    pub fn summary(&self) -> String {
        let mut s = format!(
            "{} fibers ({} pieces), {} elements, {} nodes; total length {:.4e} m, fiber volume {:.4e} m³\n",
            self.fibers, self.fiber_pieces, self.elements, self.nodes, self.total_length, self.fiber_volume
        );
        if let (Some(area), Some(vf)) = (self.cell_area, self.volume_fraction) {
            s += &format!(
                "cell area {:.4e} m², thickness {:.4e} m (fibers span {:.4e} m): solid volume fraction {:.4}\n",
                area, self.thickness, self.z_extent, vf
            );
        }
        let o = &self.orientation_in_plane;
        s += &format!(
            "orientation tensor (plan view) a11 {:.4} a22 {:.4} a12 {:.4}; out of plane a33 {:.2e}\n",
            o[0], o[1], o[2], self.orientation[2]
        );
        s += &format!(
            "{} contacts ({} candidate pairs, {:.2} per fiber), mean free segment {}",
            self.contacts,
            self.contact_candidates,
            self.contacts_per_fiber,
            self.mean_free_segment
                .map_or("-".into(), |l| format!("{l:.4e} m"))
        );
        if self.penetrating > 0 {
            s += &format!(
                "\n{} pairs start penetrating, worst overlap {:.3e} m",
                self.penetrating, self.worst_overlap
            );
        }
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::{FiberSpec, MaterialSpec, ModelDescription, NodeSpec};

    #[test]
    fn histogram_and_tensor_of_a_cross() {
        // A fiber of length 2 along x and one of length 1 along y (−y direction: same axis).
        let nodes = [
            [0.0, 0.0, 0.0],
            [2.0, 0.0, 0.0],
            [0.5, 1.0, 0.0],
            [0.5, 0.0, 0.0],
        ];
        let d = ModelDescription {
            materials: vec![MaterialSpec {
                name: "m".into(),
                young: 1.0,
                poisson: Some(0.3),
                shear: None,
            }],
            nodes: nodes
                .iter()
                .enumerate()
                .map(|(k, &x)| NodeSpec {
                    id: k as u64 + 1,
                    x,
                })
                .collect(),
            fibers: vec![
                FiberSpec {
                    id: 1,
                    nodes: vec![1, 2],
                    radius: 0.01,
                    material: "m".into(),
                },
                FiberSpec {
                    id: 2,
                    nodes: vec![3, 4],
                    radius: 0.01,
                    material: "m".into(),
                },
            ],
            ..Default::default()
        };
        let m = Model::from_description(&d).unwrap();
        let h = orientation_histogram(&m, 4);
        assert_eq!(h, vec![2.0 / 3.0, 0.0, 1.0 / 3.0, 0.0]);
        let s = network_stats(&m).unwrap();
        assert!((s.total_length - 3.0).abs() < 1e-15);
        assert!((s.orientation_in_plane[0] - 2.0 / 3.0).abs() < 1e-15);
        assert!(s.orientation_in_plane[2].abs() < 1e-15);
        assert_eq!((s.fibers, s.contacts, s.volume_fraction), (2, 0, None));
    }
}
