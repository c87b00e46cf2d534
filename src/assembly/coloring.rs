//! Greedy element coloring: no two elements of one color share a node, so a color's elements
//! can be scattered into the global matrix in parallel without write conflicts.

/// Colors the elements given by their node lists; returns the elements of each color, in
/// increasing element order.
pub fn color_elements<const K: usize>(n_nodes: usize, elements: &[[usize; K]]) -> Vec<Vec<usize>> {
    color_blocks(n_nodes, elements.iter().map(|e| &e[..]), None)
}

/// Colors blocks of any number of nodes (< `n_nodes`) so that no two blocks of a color share a
/// node other than `shared`, which any number of blocks of a color may hold (the caller then
/// accumulates what lands on it separately); returns the blocks of each color in increasing order.
pub fn color_blocks<'a>(
    n_nodes: usize,
    blocks: impl Iterator<Item = &'a [usize]>,
    shared: Option<usize>,
) -> Vec<Vec<usize>> {
    // Colors already used at each node (a handful per node in fiber networks).
    let mut used: Vec<Vec<usize>> = vec![Vec::new(); n_nodes];
    let mut colors: Vec<Vec<usize>> = Vec::new();
    for (e, all) in blocks.enumerate() {
        let nodes = || all.iter().filter(|&&n| Some(n) != shared);
        let mut c = 0;
        while nodes().any(|&n| used[n].contains(&c)) {
            c += 1;
        }
        for &n in nodes() {
            used[n].push(c);
        }
        if c == colors.len() {
            colors.push(Vec::new());
        }
        colors[c].push(e);
    }
    colors
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn colors_never_share_nodes_and_cover_all() {
        // A star of 5 elements at node 0 plus a chain.
        let els = [[0, 1], [0, 2], [0, 3], [3, 4], [4, 5], [0, 5], [1, 2]];
        let colors = color_elements(6, &els);
        let mut seen: Vec<usize> = colors.iter().flatten().copied().collect();
        seen.sort_unstable();
        assert_eq!(seen, (0..els.len()).collect::<Vec<_>>());
        for c in &colors {
            let mut nodes: Vec<usize> = c.iter().flat_map(|&e| els[e]).collect();
            let n = nodes.len();
            nodes.sort_unstable();
            nodes.dedup();
            assert_eq!(nodes.len(), n, "color {c:?} shares a node");
        }
        assert_eq!(colors.len(), 4, "node 0 has degree 4");
    }

    #[test]
    fn a_shared_node_does_not_separate_blocks() {
        // Three blocks through node 0 and one through 1 and 2: with 0 shared, two colors.
        let blocks: [&[usize]; 4] = [&[0, 1], &[0, 2, 3], &[0, 4], &[1, 2]];
        let colors = color_blocks(5, blocks.iter().copied(), Some(0));
        assert_eq!(colors, vec![vec![0, 1, 2], vec![3]]);
        let unshared = color_blocks(5, blocks.iter().copied(), None);
        assert_eq!(unshared.len(), 3);
    }
}
