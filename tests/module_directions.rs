//! The lower modules of the root crate do not reach up: `constraints` uses no solver,
//! `generate` no file format or homogenization, `solve` no homogenization or file format, the
//! errors no file reader and none of the modules whose errors they wrap, `model` nothing
//! (before, `constraints` called `solve::locate`, `error` took `InputError` from `io` and
//! `CellError` from `cell` (which used `error` back), the
//! fixture catalog in `generate` read files and homogenized, and `solve::job_system` built the
//! cell problems of `homogenize`).

use std::path::{Path, PathBuf};

/// (module, the modules it must not use).
const FORBIDDEN: &[(&str, &[&str])] = &[
    (
        "model",
        &[
            "constraints",
            "solve",
            "homogenize",
            "io",
            "generate",
            "bench",
            "assembly",
        ],
    ),
    (
        "input_error",
        &["error", "io", "solve", "homogenize", "generate", "bench"],
    ),
    (
        "error",
        &[
            "io",
            "solve",
            "homogenize",
            "generate",
            "bench",
            "cell",
            "assembly",
        ],
    ),
    (
        "constraints",
        &["solve", "homogenize", "io", "generate", "bench"],
    ),
    ("generate", &["io", "homogenize", "solve", "bench"]),
    ("solve", &["homogenize", "io", "generate", "bench"]),
];

/// The `.rs` files of module `name` (a file or a folder of `src`).
fn files(src: &Path, name: &str) -> Vec<PathBuf> {
    let file = src.join(format!("{name}.rs"));
    if file.exists() {
        return vec![file];
    }
    let mut out = Vec::new();
    let mut dirs = vec![src.join(name)];
    while let Some(dir) = dirs.pop() {
        for entry in std::fs::read_dir(&dir).expect("module folder") {
            let path = entry.expect("entry").path();
            if path.is_dir() {
                dirs.push(path);
            } else if path.extension().is_some_and(|e| e == "rs") {
                out.push(path);
            }
        }
    }
    out
}

/// The top-level modules a line names after `crate::` (also in `crate::{a, b::c}`).
fn used_modules(line: &str) -> Vec<String> {
    let ident = |s: &str| -> String {
        s.trim_start()
            .chars()
            .take_while(|c| c.is_alphanumeric() || *c == '_')
            .collect()
    };
    let mut out = Vec::new();
    for (i, _) in line.match_indices("crate::") {
        let rest = &line[i + "crate::".len()..];
        match rest.strip_prefix('{') {
            Some(group) => {
                let inner = group.split('}').next().unwrap_or("");
                out.extend(inner.split(',').map(ident));
            }
            None => out.push(ident(rest)),
        }
    }
    out
}

#[test]
fn lower_modules_do_not_use_higher_ones() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut lines = 0;
    for (module, forbidden) in FORBIDDEN {
        let paths = files(&src, module);
        assert!(!paths.is_empty(), "no files for {module}");
        for path in paths {
            let text = std::fs::read_to_string(&path).expect("read");
            // Outside the unit tests, and not in comments.
            let code = text.split("#[cfg(test)]").next().unwrap_or("");
            for line in code.lines().map(str::trim).filter(|l| !l.starts_with("//")) {
                lines += 1;
                for used in used_modules(line) {
                    assert!(
                        !forbidden.contains(&used.as_str()),
                        "{} uses {used}: {line}",
                        path.display()
                    );
                }
            }
        }
    }
    assert!(lines > 1000, "only {lines} lines read");
}

#[test]
fn the_scan_sees_paths_and_groups() {
    assert_eq!(used_modules("crate::solve::locate(e)"), ["solve"]);
    assert_eq!(
        used_modules("use crate::{io, homogenize::Curve};"),
        ["io", "homogenize"]
    );
}
