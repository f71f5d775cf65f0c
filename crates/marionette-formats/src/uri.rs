//! Files a model names (a glTF buffer or image URI, a CSE169 skin's texture): they stay
//! inside the model's folder. Opening a downloaded model never reads other files of the user.

use std::path::{Path, PathBuf};

use super::error::excerpt;

/// The file a model's relative `uri` names: percent-decoded, resolved against the model's
/// folder, and refused when it is absolute, has a scheme, or leaves that folder (by `..` or
/// through a link). Opening a downloaded model never reads other files of the user.
pub fn beside_uri(model: &Path, uri: &str) -> Result<PathBuf, String> {
    let scheme = uri.split_once(':').is_some_and(|(s, _)| {
        s.chars().next().is_some_and(|c| c.is_ascii_alphabetic())
            && s.chars().all(|c| c.is_ascii_alphanumeric() || "+-.".contains(c))
    });
    if scheme {
        return Err(format!("expected a relative path, found `{}` (a URI with a scheme)", excerpt(uri)));
    }
    let decoded = percent_decoded(uri).ok_or_else(|| format!("expected a URI, found `{}`", excerpt(uri)))?;
    inside_folder(model, &decoded)
}

/// The file `name` (a relative path) names beside the model file `model`; refused when it is
/// absolute or leaves the model's folder (by `..` or through a link).
pub fn inside_folder(model: &Path, name: &str) -> Result<PathBuf, String> {
    let decoded = name;
    if decoded.is_empty() {
        return Err("expected a file name, found an empty path".into());
    }
    if decoded.starts_with('/') || decoded.contains('\\') || Path::new(decoded).is_absolute() {
        return Err(format!("expected a path relative to the model's folder, found `{}`", excerpt(decoded)));
    }
    let mut depth = 0usize;
    for part in decoded.split('/') {
        match part {
            "" | "." => {}
            ".." => {
                depth = depth.checked_sub(1).ok_or_else(|| {
                    format!("expected a file inside the model's folder, found `{}`, which leaves it", excerpt(decoded))
                })?
            }
            _ => depth += 1,
        }
    }
    let folder = model.parent().filter(|d| !d.as_os_str().is_empty()).unwrap_or(Path::new("."));
    let file = folder.join(decoded);
    // Through links too: the file's real place must be inside the folder's.
    let (real_folder, real_file) = (folder.canonicalize(), file.canonicalize());
    if let (Ok(real_folder), Ok(real_file)) = (real_folder, real_file)
        && !real_file.starts_with(&real_folder)
    {
        return Err(format!(
            "expected a file inside the model's folder, found `{}`, a link out of it",
            excerpt(decoded)
        ));
    }
    Ok(file)
}

/// `%XX` escapes decoded (none when an escape is malformed or the result is not UTF-8).
fn percent_decoded(uri: &str) -> Option<String> {
    let bytes = uri.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        if bytes[i] == b'%' {
            let hex = std::str::from_utf8(bytes.get(i + 1..i + 3)?).ok()?;
            out.push(u8::from_str_radix(hex, 16).ok()?);
            i += 3;
        } else {
            out.push(bytes[i]);
            i += 1;
        }
    }
    String::from_utf8(out).ok()
}

/// The bytes of a `data:` URI (`data:[media type];base64,…`), or none when `uri` is not
/// one. glTF embeds buffers and images this way; only base64 payloads are read.
pub fn data_uri(uri: &str) -> Option<Result<Vec<u8>, String>> {
    use base64::Engine;
    let rest = uri.strip_prefix("data:")?;
    let Some((media, payload)) = rest.split_once(',') else {
        return Some(Err(format!("expected `data:…,` and the data, found `{}`", excerpt(uri))));
    };
    if !media.ends_with(";base64") {
        return Some(Err(format!("expected a base64 data URI, found `data:{}`", excerpt(media))));
    }
    Some(
        base64::engine::general_purpose::STANDARD
            .decode(payload.trim_end())
            .map_err(|e| format!("expected base64 data after `data:{}`, {e}", excerpt(media))),
    )
}

/// The bytes a model's URI holds (`data:`) or names (a file beside the model).
pub fn bytes(model: &Path, uri: &str) -> Result<Vec<u8>, String> {
    match data_uri(uri) {
        Some(bytes) => bytes,
        None => beside_uri(model, uri).and_then(|file| super::error::read_file(&file).map_err(|e| e.to_string())),
    }
}
