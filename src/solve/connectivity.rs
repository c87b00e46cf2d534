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
    let n = model.nodes.len();
    let mut parent: Vec<usize> = (0..n).collect();
    for e in model.elements() {
        let (a, b) = (find(&mut parent, e.nodes[0]), find(&mut parent, e.nodes[1]));
        if a != b {
            parent[a.max(b)] = a.min(b);
        }
    }
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
