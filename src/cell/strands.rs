//! Strands: the fibers of a model that continue one another end to end. A fiber that leaves a
//! periodic cell is written as pieces — one ending on a face, the next starting at the periodic
//! twin of that end on the opposite face — and a fiber may be split at a node it shares with
//! the next piece. A crossing on such a joint is one crossing of one strand, although the
//! search sees it on both pieces (the contact search merges duplicates per pair of strands),
//! and the pieces are one physical fiber (the statistics count strands).

use super::{independent_node, Periodicity};
use crate::model::Model;

/// The strand of every fiber (an index shared by the fibers of one strand): two fibers are
/// joined where they end at one node, directly or as periodic twins (the same independent
/// node), and nothing else meets there — a continuation, not a junction of several yarns, whose
/// branches cross other fibers at distinct points however close.
pub(crate) fn strand_of_fibers(model: &Model, cell: Option<&Periodicity>) -> Vec<usize> {
    let canonical = |n: usize| independent_node(cell, n);
    // Element ends at each independent node, and the fibers that end there.
    let mut degree = vec![0u32; model.nodes.len()];
    for e in model.elements() {
        for &n in &e.nodes {
            degree[canonical(n)] += 1;
        }
    }
    let mut ending: Vec<Vec<usize>> = vec![Vec::new(); model.nodes.len()];
    for (f, fiber) in model.fibers.iter().enumerate() {
        let ends = [fiber.nodes.first(), fiber.nodes.last()];
        for &n in ends.into_iter().flatten() {
            ending[canonical(n)].push(f);
        }
    }
    let mut parent: Vec<usize> = (0..model.fibers.len()).collect();
    for (node, fibers) in ending.iter().enumerate() {
        if let [a, b] = fibers[..] {
            if degree[node] == 2 {
                union(&mut parent, a, b);
            }
        }
    }
    (0..parent.len()).map(|f| root(&mut parent, f)).collect()
}

fn root(parent: &mut [usize], mut f: usize) -> usize {
    while parent[f] != f {
        parent[f] = parent[parent[f]];
        f = parent[f];
    }
    f
}

fn union(parent: &mut [usize], a: usize, b: usize) {
    let (ra, rb) = (root(parent, a), root(parent, b));
    if ra != rb {
        parent[ra.max(rb)] = ra.min(rb);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::{FiberSpec, MaterialSpec, ModelDescription, NodeSpec};

    #[test]
    fn fibers_meeting_end_to_end_form_one_strand_and_crossing_fibers_do_not() {
        // Fibers 1 → 2 → 3 end to end along x; fiber 4 shares fiber 2's middle node only;
        // fibers 5 and 6 end where fiber 3 ends (a junction of three, not a continuation).
        let x = [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [2.0, 0.0, 0.0],
            [2.5, 0.0, 0.0],
            [3.0, 0.0, 0.0],
            [4.0, 0.0, 0.0],
            [2.5, -1.0, 0.0],
            [2.5, 1.0, 0.0],
            [4.0, 1.0, 0.0],
            [5.0, 0.0, 0.0],
        ];
        let fibers = [
            vec![1, 2],
            vec![2, 3, 4, 5],
            vec![5, 6],
            vec![7, 4, 8],
            vec![6, 9],
            vec![6, 10],
        ];
        let d = ModelDescription {
            materials: vec![MaterialSpec {
                name: "m".into(),
                young: 1e9,
                poisson: Some(0.3),
                shear: None,
            }],
            nodes: (0..x.len())
                .map(|i| NodeSpec {
                    id: i as u64 + 1,
                    x: x[i],
                })
                .collect(),
            fibers: fibers
                .iter()
                .enumerate()
                .map(|(i, nodes)| FiberSpec {
                    id: i as u64 + 1,
                    nodes: nodes.clone(),
                    radius: 0.01,
                    material: "m".into(),
                })
                .collect(),
            ..Default::default()
        };
        let model = Model::from_description(&d).unwrap();
        assert_eq!(strand_of_fibers(&model, None), vec![0, 0, 0, 3, 4, 5]);
    }
}
