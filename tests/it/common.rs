//! Helpers shared by the tests.

use std::path::{Path, PathBuf};

use glam::{Mat4, Vec3};

/// The real data folder from `MARIONETTE_DATA`. Tests that need it carry
/// `#[cfg_attr(not(marionette_data), ignore = "…")]` (build.rs sets the cfg when the variable
/// is set at build time), so without the data they are reported as ignored, not passed.
///
/// # Panics
/// When the variable is unset at run time (the binary was built with it) or not a folder.
pub fn data_dir() -> PathBuf {
    optional_data_dir().expect("MARIONETTE_DATA is not set (the tests were built with it; set it again)")
}

/// The real data folder when `MARIONETTE_DATA` is set (for tests that only do more with it).
pub fn optional_data_dir() -> Option<PathBuf> {
    let dir = PathBuf::from(std::env::var_os("MARIONETTE_DATA")?);
    assert!(dir.is_dir(), "MARIONETTE_DATA={} is not a folder", dir.display());
    Some(dir)
}

pub fn path(s: &str) -> &Path {
    Path::new(s)
}

pub fn assert_mat_close(a: Mat4, b: Mat4, tol: f32) {
    let (a, b) = (a.to_cols_array(), b.to_cols_array());
    for k in 0..16 {
        assert!((a[k] - b[k]).abs() <= tol, "matrices differ at {k}: {a:?} vs {b:?}");
    }
}

pub fn assert_vec_close(a: Vec3, b: Vec3, tol: f32) {
    assert!(a.distance(b) <= tol, "{a} vs {b} (distance {})", a.distance(b));
}

/// A unique scratch folder for one test.
pub fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("marionette-test-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// A GLB with its JSON chunk edited by `edit` (the binary chunk as it was).
pub fn glb_with_json(glb: &[u8], edit: impl FnOnce(&mut serde_json::Value)) -> Vec<u8> {
    let u32_at = |at: usize| u32::from_le_bytes(glb[at..at + 4].try_into().unwrap()) as usize;
    let json_len = u32_at(12);
    let mut json: serde_json::Value = serde_json::from_slice(&glb[20..20 + json_len]).unwrap();
    edit(&mut json);
    let mut text = serde_json::to_vec(&json).unwrap();
    text.resize(text.len().div_ceil(4) * 4, b' ');
    let rest = &glb[20 + json_len..];
    let mut out = b"glTF".to_vec();
    out.extend(2u32.to_le_bytes());
    out.extend(((20 + text.len() + rest.len()) as u32).to_le_bytes());
    out.extend((text.len() as u32).to_le_bytes());
    out.extend(b"JSON");
    out.extend(&text);
    out.extend(rest);
    out
}

/// A file's characters posed by its clip `clip` at `t` seconds (by its node transforms
/// without one), as `export FILE --clip CLIP --time T --out F.obj` writes them.
pub fn posed_at(path: &std::path::Path, clip: Option<&str>, t: f32) -> Vec<Vec3> {
    use marionette::document::options::{PoseOptions, posed_file};
    let options = PoseOptions { clip: clip.map(str::to_string), time: Some(t), ..PoseOptions::default() };
    posed_file(path, &options).unwrap_or_else(|e| panic!("{}: {e}", path.display())).0
}
