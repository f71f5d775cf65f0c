//! OFF meshes (`OFF`, `nV nF nE`, vertices, then `k i0 i1 ...` faces, 0-based).

use std::io::BufRead;
use std::path::Path;

use glam::Vec3;

use super::error::{FormatError, parse_number, read_lines};
use super::obj::ObjMesh;

/// Parses an ASCII OFF file. `#` comments and blank lines are skipped; polygons are
/// fan-triangulated; extra numbers after a face (colours) are ignored.
pub fn parse_off(reader: impl BufRead, path: &Path) -> Result<ObjMesh, FormatError> {
    let lines = read_lines(reader, path)?;
    let mut lines = lines.into_iter().filter(|(_, l)| {
        let t = l.trim();
        !t.is_empty() && !t.starts_with('#')
    });
    let (n, header) =
        lines.next().ok_or_else(|| FormatError::syntax(path, 1, "expected `OFF`, found an empty file"))?;
    let mut header_tokens = header.split_whitespace();
    if header_tokens.next() != Some("OFF") {
        return Err(FormatError::syntax(
            path,
            n,
            format!("expected `OFF`, found `{}`", super::error::excerpt(header.trim())),
        ));
    }
    // The counts may follow OFF on the same line.
    let rest: Vec<&str> = header_tokens.collect();
    let (counts_line, counts) = if rest.is_empty() {
        let (n, l) = lines.next().ok_or_else(|| {
            FormatError::syntax(path, n + 1, "expected `vertices faces edges`, found the end of the file")
        })?;
        (n, l.split_whitespace().map(str::to_string).collect::<Vec<_>>())
    } else {
        (n, rest.iter().map(|s| s.to_string()).collect())
    };
    if counts.len() < 2 {
        return Err(FormatError::syntax(
            path,
            counts_line,
            format!("expected 3 counts (vertices faces edges), found {}", counts.len()),
        ));
    }
    let vertex_count: usize = parse_number(&counts[0], path, counts_line)?;
    let face_count: usize = parse_number(&counts[1], path, counts_line)?;
    let mut mesh = ObjMesh::default();
    for _ in 0..vertex_count {
        let (n, l) = lines.next().ok_or_else(|| {
            FormatError::syntax(
                path,
                counts_line,
                format!("expected {vertex_count} vertices, found {} before the end of the file", mesh.positions.len()),
            )
        })?;
        let t: Vec<&str> = l.split_whitespace().collect();
        if t.len() < 3 {
            return Err(FormatError::syntax(path, n, format!("expected 3 numbers (x y z), found {}", t.len())));
        }
        mesh.positions.push(Vec3::new(
            parse_number(t[0], path, n)?,
            parse_number(t[1], path, n)?,
            parse_number(t[2], path, n)?,
        ));
    }
    for f in 0..face_count {
        let (n, l) = lines.next().ok_or_else(|| {
            FormatError::syntax(
                path,
                counts_line,
                format!("expected {face_count} faces, found {f} before the end of the file"),
            )
        })?;
        let t: Vec<&str> = l.split_whitespace().collect();
        let k: usize = parse_number(t[0], path, n)?;
        if k < 3 || t.len() - 1 < k {
            return Err(FormatError::syntax(
                path,
                n,
                format!("expected a polygon `k i0 .. i(k-1)` with k >= 3, found `{}`", super::error::excerpt(l.trim())),
            ));
        }
        let idx = t[1..=k]
            .iter()
            .map(|s| {
                let i: usize = parse_number(s, path, n)?;
                if i >= vertex_count {
                    return Err(FormatError::syntax(
                        path,
                        n,
                        format!("expected a vertex index below {vertex_count}, found {i}"),
                    ));
                }
                Ok(i as u32)
            })
            .collect::<Result<Vec<_>, _>>()?;
        for j in 1..k - 1 {
            mesh.triangles.push([idx[0], idx[j], idx[j + 1]]);
        }
    }
    Ok(mesh)
}
