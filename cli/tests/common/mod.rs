//! What the CLI's test binaries share: the repository's root, where the binary runs and the
//! fixtures' relative paths start. (Each test binary uses a part of it.)
#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::process::Command;

/// The repository's root.
pub const ROOT: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/..");

/// `path` relative to the repository's root.
pub fn at_root(path: &str) -> PathBuf {
    Path::new(ROOT).join(path)
}

/// The `fibercell` binary, run in the repository's root.
pub fn fibercell() -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_fibercell"));
    c.current_dir(ROOT);
    c
}
