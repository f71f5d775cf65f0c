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
