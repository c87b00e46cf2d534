//! All-or-nothing file output: write a temporary file beside the target, then rename it.

use crate::Error;
use std::io::Write;
use std::path::Path;

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
    let mut tmp = tempfile::NamedTempFile::new_in(dir).map_err(|e| err(e.to_string()))?;
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
}
