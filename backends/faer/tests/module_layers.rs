//! The solve modules depend in one direction: each file imports (outside its tests) only
//! modules of a lower layer, so no two import each other in a circle (before, `block_solve`,
//! `dense_forward`, `sparse_forward`, `top_columns` and `prefetch` did).

/// Bottom first; a module may import the ones of lower layers only.
const LAYERS: &[&[&str]] = &[
    &["dense_llt", "prefault", "supernodes"],
    &["symbolic"],
    &[
        "block_tree",
        "column_layout",
        "permute",
        "pivots",
        "supernodal_llt",
    ],
    &["block_kernels", "prefetch", "top_columns"],
    &["dense_forward"],
    &["block_solve", "block_solve_many", "sparse_forward"],
    &["cholesky", "lu"],
];

fn layer(module: &str) -> Option<usize> {
    LAYERS.iter().position(|l| l.contains(&module))
}

#[test]
fn every_module_imports_only_lower_layers() {
    let src = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut checked = 0;
    for entry in std::fs::read_dir(&src).expect("src") {
        let path = entry.expect("entry").path();
        let name = path
            .file_stem()
            .and_then(|s| s.to_str())
            .expect("name")
            .to_string();
        if name == "lib" || name == "test_matrices" {
            continue;
        }
        let own = layer(&name).unwrap_or_else(|| panic!("{name}.rs is in no layer of LAYERS"));
        let text = std::fs::read_to_string(&path).expect("read");
        // Outside the unit tests: everything before `#[cfg(test)]`.
        let code = text.split("#[cfg(test)]").next().unwrap_or("");
        for line in code.lines().map(str::trim) {
            let Some(rest) = line.strip_prefix("use crate::") else {
                continue;
            };
            let module: String = rest
                .chars()
                .take_while(|c| c.is_alphanumeric() || *c == '_')
                .collect();
            let Some(theirs) = layer(&module) else {
                continue; // the crate root's re-exports
            };
            assert!(
                theirs < own,
                "{name} (layer {own}) imports {module} (layer {theirs})"
            );
            checked += 1;
        }
    }
    assert!(checked >= 15, "only {checked} imports checked");
}
