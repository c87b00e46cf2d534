//! Load paths across the cell: union–find over the independent nodes with, for every node, its
//! offset (in periods) from its component's root. An element closing a loop with a non-zero net
//! offset is a chain of fibers that wraps around the cell in that direction.

use super::{CellError, Periodicity};
use crate::model::Model;

fn find(parent: &mut [usize], offset: &mut [[i32; 2]], i: usize) -> (usize, [i32; 2]) {
    if parent[i] == i {
        return (i, [0, 0]);
    }
    let (root, o) = find(parent, offset, parent[i]);
    offset[i] = [offset[i][0] + o[0], offset[i][1] + o[1]];
    parent[i] = root;
    (root, offset[i])
}

/// Checks that every fiber is connected to the others and that chains of fibers cross the cell
/// in x and in y. `links` are extra node pairs joined inside the cell (the contacts), each with
/// the period shift of the second node's image.
pub fn check_percolation(
    model: &Model,
    p: &Periodicity,
    links: &[([usize; 2], [i32; 2])],
) -> Result<(), CellError> {
    let n = model.nodes.len();
    let mut parent: Vec<usize> = (0..n).collect();
    let mut offset = vec![[0i32; 2]; n];
    let mut wraps = [false; 2];
    let resolve = |i: usize| p.master[i].unwrap_or((i, [0, 0]));
    let edges = model
        .elements()
        .iter()
        .map(|e| (e.nodes, [0, 0]))
        .chain(links.iter().copied());
    for ([na, nb], image) in edges {
        let (a, sa) = resolve(na);
        let (b, sb) = resolve(nb);
        let sb = [sb[0] + image[0], sb[1] + image[1]];
        // Node b's image sits at offset sb − sa from node a's image.
        let want = [sb[0] - sa[0], sb[1] - sa[1]];
        let (ra, oa) = find(&mut parent, &mut offset, a);
        let (rb, ob) = find(&mut parent, &mut offset, b);
        if ra == rb {
            for k in 0..2 {
                if ob[k] - oa[k] != want[k] {
                    wraps[k] = true;
                }
            }
        } else {
            // Attach rb under ra: offset(rb) = oa + want − ob.
            parent[rb] = ra;
            offset[rb] = [oa[0] + want[0] - ob[0], oa[1] + want[1] - ob[1]];
        }
    }
    // Every fiber in the component of the first fiber.
    let root_of = |parent: &mut Vec<usize>, offset: &mut Vec<[i32; 2]>, node: usize| {
        find(parent, offset, resolve(node).0).0
    };
    let first = root_of(&mut parent, &mut offset, model.fibers[0].nodes[0]);
    let disconnected: Vec<u64> = model
        .fibers
        .iter()
        .filter(|f| root_of(&mut parent, &mut offset, f.nodes[0]) != first)
        .map(|f| f.id)
        .collect();
    if !disconnected.is_empty() {
        return Err(CellError::Disconnected {
            fibers: disconnected,
        });
    }
    for (k, name) in ["x", "y"].into_iter().enumerate() {
        if !wraps[k] {
            return Err(CellError::NoPercolation { direction: name });
        }
    }
    Ok(())
}
