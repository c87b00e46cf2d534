//! Every connected group of fibers needs at least one support; otherwise it floats and the
//! stiffness is singular. Checked before factorizing, so the error can name the fibers.

use crate::model::Model;
use crate::Error;

fn find(parent: &mut [usize], mut i: usize) -> usize {
    while parent[i] != i {
        parent[i] = parent[parent[i]];
        i = parent[i];
    }
    i
}

/// Fails with [`Error::Unsupported`] naming the fibers of the first group (in fiber order)
/// that no support touches.
pub fn check_supported(model: &Model) -> Result<(), Error> {
    if model.cell.is_some() && model.supports.is_empty() {
        return Err(Error::CellWithoutSupports);
    }
    check_supported_with(model, &[])
}

/// The root of every node's connected group: nodes joined by the elements and by each group of
/// `links` (contact blocks).
pub(crate) fn node_roots(model: &Model, links: &[&[usize]]) -> Vec<usize> {
    let mut parent = joined(model, links);
    (0..parent.len()).map(|i| find(&mut parent, i)).collect()
}

/// The union-find forest of the nodes joined by the elements and by each group of `links`.
fn joined(model: &Model, links: &[&[usize]]) -> Vec<usize> {
    let n = model.nodes.len();
    let mut parent: Vec<usize> = (0..n).collect();
    let join = |parent: &mut Vec<usize>, x: usize, y: usize| {
        let (a, b) = (find(parent, x), find(parent, y));
        if a != b {
            parent[a.max(b)] = a.min(b);
        }
    };
    for e in model.elements() {
        join(&mut parent, e.nodes[0], e.nodes[1]);
    }
    for group in links {
        for w in group.windows(2) {
            join(&mut parent, w[0], w[1]);
        }
    }
    parent
}

/// Like [`check_supported`], with extra groups of nodes joined (the blocks of the contacts that
/// are currently closed): a fiber held only by open contacts is reported.
pub fn check_supported_with(model: &Model, links: &[&[usize]]) -> Result<(), Error> {
    let n = model.nodes.len();
    let mut parent = joined(model, links);
    let mut supported = vec![false; n];
    for s in &model.supports {
        let r = find(&mut parent, s.node);
        supported[r] = true;
    }
    let mut bad_root = None;
    let mut fibers = Vec::new();
    for f in &model.fibers {
        let r = find(&mut parent, f.nodes[0]);
        if supported[r] {
            continue;
        }
        if *bad_root.get_or_insert(r) == r {
            fibers.push(f.id);
        }
    }
    if fibers.is_empty() {
        Ok(())
    } else {
        Err(Error::Unsupported { fibers })
    }
}
