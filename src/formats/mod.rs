//! Readers and writers of the course formats. Each parser reads from `impl BufRead` and
//! fails with `path:line: what was expected, what was found`; `load_*` wrap them for files.
//! No Bevy here.

pub mod character;
pub mod cse169;
pub mod error;
pub mod homer;
pub mod mit6837;
pub mod obj;
pub mod off;
pub mod scene;
pub mod smpl;

pub use character::{CharacterSource, load_character};
pub use error::FormatError;

/// Writes a whole file or nothing: the content goes to a temporary file beside `path`,
/// which is flushed, synced and renamed over `path` only when every write succeeded.
pub fn write_atomically(
    path: &std::path::Path,
    write: impl FnOnce(&mut std::io::BufWriter<std::fs::File>) -> std::io::Result<()>,
) -> std::io::Result<()> {
    use std::io::Write;
    let dir = path.parent().filter(|d| !d.as_os_str().is_empty()).unwrap_or(std::path::Path::new("."));
    let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    let tmp = dir.join(format!(".{name}.{}.tmp", std::process::id()));
    let result = (|| {
        let mut w = std::io::BufWriter::new(std::fs::File::create(&tmp)?);
        write(&mut w)?;
        w.flush()?;
        w.get_ref().sync_all()?;
        drop(w);
        std::fs::rename(&tmp, path)
    })();
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    result
}
