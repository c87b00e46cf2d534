//! All-or-nothing file output: write a temporary file beside the target, then rename it.
//!
//! The temporary files are named `.fibercell-XXXXXX.tmp` and listed while they are written,
//! so that a program interrupted mid-write can remove them ([`remove_unfinished_outputs`],
//! which the CLI calls on SIGINT, SIGTERM and SIGHUP).

use crate::Error;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::Mutex;

/// The temporary files being written now.
static IN_FLIGHT: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());

/// Writes `contents` to `path` completely or not at all.
pub fn write_atomic(path: &Path, contents: &[u8]) -> Result<(), Error> {
    let err = |m: String| Error::Output {
        path: path.display().to_string(),
        message: m,
    };
    let dir = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    let mut tmp = tempfile::Builder::new()
        .prefix(".fibercell-")
        .suffix(".tmp")
        .tempfile_in(dir)
        .map_err(|e| err(e.to_string()))?;
    let listed = tmp.path().to_path_buf();
    in_flight(|files| files.push(listed.clone()));
    let written = (|| {
        tmp.write_all(contents).map_err(|e| err(e.to_string()))?;
        tmp.as_file().sync_all().map_err(|e| err(e.to_string()))?;
        // Temporary files are created private (0600); outputs get ordinary permissions.
        #[cfg(unix)]
        {
            use std::os::unix::fs::PermissionsExt;
            tmp.as_file()
                .set_permissions(std::fs::Permissions::from_mode(0o644))
                .map_err(|e| err(e.to_string()))?;
        }
        tmp.persist(path).map_err(|e| err(e.error.to_string()))?;
        Ok(())
    })();
    in_flight(|files| files.retain(|f| f != &listed));
    written
}

/// Runs `f` on the list of temporary files (a poisoned lock is still usable: the list is
/// only ever pushed to and filtered).
fn in_flight<R>(f: impl FnOnce(&mut Vec<PathBuf>) -> R) -> R {
    let mut files = IN_FLIGHT.lock().unwrap_or_else(|e| e.into_inner());
    f(&mut files)
}

/// Prepares the results folder `dir` of a command whose JSON document `marker` is written last,
/// so that a folder holding it is complete: creates the folder and removes a `marker` left by
/// an earlier run (a run interrupted now must not leave an old one looking complete).
pub fn begin_results(dir: &Path, marker: &str) -> Result<(), Error> {
    let err = |path: &Path, e: std::io::Error| Error::Output {
        path: path.display().to_string(),
        message: e.to_string(),
    };
    std::fs::create_dir_all(dir).map_err(|e| err(dir, e))?;
    let marker = dir.join(marker);
    match std::fs::remove_file(&marker) {
        Err(e) if e.kind() != std::io::ErrorKind::NotFound => Err(err(&marker, e)),
        _ => Ok(()),
    }
}

/// Writes the result files `files` (name, contents) into `dir` in their order, each atomically,
/// after [`begin_results`] with the last one as the marker: a folder holding it is complete.
/// Returns their paths.
pub fn write_results(dir: &Path, files: &[(&str, &[u8])]) -> Result<Vec<PathBuf>, Error> {
    if let Some((marker, _)) = files.last() {
        begin_results(dir, marker)?;
    }
    files
        .iter()
        .map(|(name, bytes)| {
            let path = dir.join(name);
            write_atomic(&path, bytes)?;
            Ok(path)
        })
        .collect()
}

/// Removes the temporary files of writes still under way (for a program that is being
/// interrupted); returns how many it removed.
pub fn remove_unfinished_outputs() -> usize {
    in_flight(|files| {
        let removed = files
            .drain(..)
            .filter(|f| std::fs::remove_file(f).is_ok())
            .count();
        removed
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A write under way is listed under its `.fibercell-*.tmp` name and removed by
    /// `remove_unfinished_outputs`; a finished one is not listed.
    #[test]
    fn unfinished_outputs_are_listed_and_removed() {
        let dir = tempfile::tempdir().expect("dir");
        write_atomic(&dir.path().join("done.txt"), b"done").expect("written");
        assert!(in_flight(|f| f.is_empty()));
        // A write interrupted after its temporary file was created.
        let tmp = tempfile::Builder::new()
            .prefix(".fibercell-")
            .suffix(".tmp")
            .tempfile_in(dir.path())
            .expect("tmp");
        let (_, path) = tmp.keep().expect("kept");
        in_flight(|f| f.push(path.clone()));
        assert_eq!(remove_unfinished_outputs(), 1);
        assert!(!path.exists());
        let names: Vec<String> = std::fs::read_dir(dir.path())
            .expect("list")
            .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
            .collect();
        assert_eq!(names, ["done.txt"]);
    }
}
