//! Readers and writers of the course formats. Each parser reads from `impl BufRead` and
//! fails with `path:line: what was expected, what was found`; `load_*` wrap them for files.
//! No Bevy here.

pub mod bmp;
pub mod bvh;
pub mod character;
pub mod checks;
pub mod cse169;
pub mod cse169_skin;
pub mod error;
pub mod fbx;
pub mod gltf;
pub mod gltf_check;
pub mod gltf_import;
pub mod gltf_materials;
pub mod gltf_out_materials;
pub mod homer;
pub mod keypoints;
pub mod limits;
pub mod mit6837;
pub mod node_tree;
pub mod obj;
pub mod off;
pub mod part;
pub mod puppet;
pub mod scene;
pub mod smpl;
pub mod stage;
pub mod uri;
pub mod vrm;
pub mod weight_warnings;

pub use character::{CharacterSource, has_parts, load_character, load_parts};

/// A keyframed clip from a file: a CSE169 `.anim`, or the motion of a `.bvh`.
pub fn load_clip(path: &std::path::Path) -> Result<marionette_rig::anim::Clip, FormatError> {
    let input = error::open(path)?;
    if path.extension().is_some_and(|e| e.eq_ignore_ascii_case("bvh")) {
        Ok(bvh::parse_bvh(input, path)?.clip)
    } else {
        cse169_skin::parse_anim(input, path)
    }
}
pub use error::FormatError;

/// Writes a whole file or nothing: the content goes to a new temporary file beside `path`
/// (an unpredictable name, created exclusively, so no symlink or other file is followed),
/// which is flushed, synced and renamed over `path` only when every write succeeded; then
/// the folder is synced so the rename itself survives a crash.
pub fn write_atomically(
    path: &std::path::Path,
    write: impl FnOnce(&mut std::io::BufWriter<std::fs::File>) -> std::io::Result<()>,
) -> std::io::Result<()> {
    use std::io::Write;
    let dir = path.parent().filter(|d| !d.as_os_str().is_empty()).unwrap_or(std::path::Path::new("."));
    let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    let (tmp, file) = create_temporary(dir, &name)?;
    let result = (|| {
        let mut w = std::io::BufWriter::new(file);
        write(&mut w)?;
        w.flush()?;
        w.get_ref().sync_all()?;
        drop(w);
        std::fs::rename(&tmp, path)?;
        sync_dir(dir)
    })();
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    result
}

/// A new file `.NAME.RANDOM.tmp` in `dir`, created with `create_new` (never an existing
/// file or a symlink's target); a few names are tried.
fn create_temporary(dir: &std::path::Path, name: &str) -> std::io::Result<(std::path::PathBuf, std::fs::File)> {
    use std::hash::{BuildHasher, Hasher};
    let mut last_error = None;
    for attempt in 0..8u64 {
        // RandomState is seeded from the OS's randomness: an unguessable name.
        let mut hasher = std::collections::hash_map::RandomState::new().build_hasher();
        hasher.write_u64(attempt ^ u64::from(std::process::id()));
        let tmp = dir.join(format!(".{name}.{:016x}.tmp", hasher.finish()));
        match std::fs::OpenOptions::new().write(true).create_new(true).open(&tmp) {
            Ok(file) => return Ok((tmp, file)),
            Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => last_error = Some(e),
            Err(e) => return Err(e),
        }
    }
    Err(last_error.unwrap_or_else(|| std::io::Error::other("no free temporary name")))
}

/// Flushes a folder's entries to disk (a no-op where folders cannot be opened).
fn sync_dir(dir: &std::path::Path) -> std::io::Result<()> {
    #[cfg(unix)]
    std::fs::File::open(dir)?.sync_all()?;
    #[cfg(not(unix))]
    let _ = dir;
    Ok(())
}

#[cfg(test)]
mod tests;
