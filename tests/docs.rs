//! The documentation stays true to the repository: the README is a newcomer's page (at most
//! 400 lines), every relative link of the README and of `docs/` reaches a file (and a heading,
//! when it names one), and `docs/architecture.md` lists every source folder. (The Rust blocks
//! of these pages run as doctests: `doc_examples` in `src/lib.rs`; their command, Python and C
//! blocks run in `.ci/doc_blocks.py`.)

use std::path::{Path, PathBuf};

fn pages() -> Vec<PathBuf> {
    let mut pages = vec![PathBuf::from("README.md")];
    let mut docs: Vec<PathBuf> = std::fs::read_dir("docs")
        .expect("docs/ exists")
        .map(|e| e.expect("entry").path())
        .filter(|p| p.extension().is_some_and(|e| e == "md"))
        .collect();
    docs.sort();
    assert!(!docs.is_empty(), "no pages in docs/");
    pages.extend(docs);
    pages
}

/// GitHub's anchor of a heading: lower case, spaces to hyphens, other punctuation dropped.
fn slug(heading: &str) -> String {
    heading
        .trim()
        .to_lowercase()
        .chars()
        .filter_map(|c| match c {
            ' ' => Some('-'),
            c if c.is_alphanumeric() || c == '-' || c == '_' => Some(c),
            _ => None,
        })
        .collect()
}

/// The lines of a page outside its code blocks.
fn prose(text: &str) -> Vec<&str> {
    let mut fence = false;
    text.lines()
        .filter(|line| {
            if line.starts_with("```") {
                fence = !fence;
                return false;
            }
            !fence
        })
        .collect()
}

/// The anchors of a page's headings.
fn anchors(text: &str) -> Vec<String> {
    prose(text)
        .into_iter()
        .filter(|line| line.starts_with('#'))
        .map(|line| slug(line.trim_start_matches('#')))
        .collect()
}

/// The targets of the Markdown links `[text](target)` of a page.
fn links(text: &str) -> Vec<String> {
    let mut out = Vec::new();
    for line in prose(text) {
        let mut rest = line;
        while let Some(i) = rest.find("](") {
            let tail = &rest[i + 2..];
            let Some(end) = tail.find(')') else { break };
            out.push(tail[..end].to_string());
            rest = &tail[end..];
        }
    }
    out
}

#[test]
fn the_readme_is_a_newcomers_page() {
    let readme = std::fs::read_to_string("README.md").expect("README");
    let lines = readme.lines().count();
    assert!(lines <= 400, "README.md has {lines} lines, more than 400");
    for section in [
        "## Install",
        "## Quick start",
        "## A model file",
        "## Commands",
        "## Rust quick start",
        "## Python quick start",
        "## C quick start",
        "## Limitations",
        "## Performance",
    ] {
        assert!(readme.contains(section), "README.md lacks {section}");
    }
}

#[test]
fn every_relative_link_reaches_a_file_and_heading() {
    let mut broken = Vec::new();
    for page in pages() {
        let text = std::fs::read_to_string(&page).expect("page");
        let dir = page.parent().unwrap_or(Path::new("")).to_path_buf();
        for target in links(&text) {
            if target.starts_with("http://") || target.starts_with("https://") {
                continue;
            }
            let (file, anchor) = match target.split_once('#') {
                Some((f, a)) => (f, Some(a)),
                None => (target.as_str(), None),
            };
            let path = if file.is_empty() {
                page.clone()
            } else {
                dir.join(file)
            };
            if !path.exists() {
                broken.push(format!("{}: {target} (no file)", page.display()));
                continue;
            }
            if let Some(a) = anchor {
                let linked = std::fs::read_to_string(&path).unwrap_or_default();
                if !anchors(&linked).iter().any(|h| h == a) {
                    broken.push(format!("{}: {target} (no heading)", page.display()));
                }
            }
        }
    }
    assert!(broken.is_empty(), "broken links:\n{}", broken.join("\n"));
}

#[test]
fn the_architecture_page_lists_every_source_folder() {
    let page = std::fs::read_to_string("docs/architecture.md").expect("architecture page");
    let mut folders = Vec::new();
    let mut stack = vec![PathBuf::from("src")];
    while let Some(dir) = stack.pop() {
        let mut has_source = false;
        for entry in std::fs::read_dir(&dir).expect("folder") {
            let path = entry.expect("entry").path();
            if path.is_dir() {
                stack.push(path);
            } else if path.extension().is_some_and(|e| e == "rs") {
                has_source = true;
            }
        }
        if has_source && dir != Path::new("src") {
            folders.push(dir);
        }
    }
    // Every crate of the workspace (`members` of the root manifest) and of the bindings.
    let manifest = std::fs::read_to_string("Cargo.toml").expect("root manifest");
    let members = manifest
        .lines()
        .find_map(|l| l.strip_prefix("members = ["))
        .expect("workspace members");
    for member in members.split('"').skip(1).step_by(2) {
        if member != "." && !folders.iter().any(|f| f == Path::new(member)) {
            folders.push(PathBuf::from(member));
        }
    }
    for top in ["backends", "bindings"] {
        for entry in std::fs::read_dir(top).expect("folder") {
            let path = entry.expect("entry").path();
            if path.join("Cargo.toml").exists() && !folders.contains(&path) {
                folders.push(path);
            }
        }
    }
    assert!(folders.len() >= 15, "only {} folders found", folders.len());
    let missing: Vec<String> = folders
        .iter()
        .map(|f| f.display().to_string())
        .filter(|f| !page.contains(&format!("`{f}`")))
        .collect();
    assert!(
        missing.is_empty(),
        "docs/architecture.md does not list: {}",
        missing.join(", ")
    );
}
