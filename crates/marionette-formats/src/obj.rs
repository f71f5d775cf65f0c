//! Wavefront OBJ positions and faces, read in source order, and an OBJ writer.
//!
//! We read OBJ ourselves rather than through tobj: tobj renumbers vertices by first use
//! in the faces (and drops unused ones), but weight files (`.attach`, SMPL skins) index
//! vertices in file order and exports must be comparable vertex by vertex. Only `v` and
//! `f` matter here; normals, texture coordinates, groups and materials are skipped.

use std::io::{BufRead, Write};
use std::path::Path;

use glam::Vec3;

use super::error::{FormatError, parse_number, read_lines};

/// Vertices in file order and triangles (polygons fan-triangulated), 0-based.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ObjMesh {
    pub positions: Vec<Vec3>,
    pub triangles: Vec<[u32; 3]>,
}

/// Parses `v x y z [w]` and `f a b c ...` lines (`a`, `a/t`, `a//n`, `a/t/n`; negative
/// indices count from the end). Faces may refer to vertices defined later.
pub fn parse_obj(reader: impl BufRead, path: &Path) -> Result<ObjMesh, FormatError> {
    let mut mesh = ObjMesh::default();
    let mut faces: Vec<(usize, Vec<i64>)> = Vec::new();
    for (line_no, line) in read_lines(reader, path)? {
        let mut tokens = line.split_whitespace();
        match tokens.next() {
            Some("v") => {
                let values: Vec<&str> = tokens.collect();
                if !(3..=4).contains(&values.len()) && values.len() != 6 && values.len() != 7 {
                    return Err(FormatError::syntax(
                        path,
                        line_no,
                        format!("expected 3 numbers after `v`, found {}", values.len()),
                    ));
                }
                let x = parse_number(values[0], path, line_no)?;
                let y = parse_number(values[1], path, line_no)?;
                let z = parse_number(values[2], path, line_no)?;
                mesh.positions.push(Vec3::new(x, y, z));
            }
            Some("f") => {
                let corners = tokens
                    .map(|t| {
                        let first = t.split('/').next().unwrap_or("");
                        first.parse::<i64>().map_err(|_| {
                            FormatError::syntax(
                                path,
                                line_no,
                                format!("expected a vertex index, found `{}`", super::error::excerpt(t)),
                            )
                        })
                    })
                    .collect::<Result<Vec<_>, _>>()?;
                if corners.len() < 3 {
                    return Err(FormatError::syntax(
                        path,
                        line_no,
                        format!("expected at least 3 vertex indices after `f`, found {}", corners.len()),
                    ));
                }
                faces.push((line_no, corners));
            }
            _ => {}
        }
    }
    let count = mesh.positions.len();
    for (line_no, corners) in faces {
        let resolved = corners
            .iter()
            .map(|&i| {
                let index = if i < 0 { count as i64 + i } else { i - 1 };
                if index < 0 || index as usize >= count {
                    Err(FormatError::syntax(
                        path,
                        line_no,
                        format!("expected a vertex index in 1..={count}, found {i}"),
                    ))
                } else {
                    Ok(index as u32)
                }
            })
            .collect::<Result<Vec<u32>, _>>()?;
        for k in 1..resolved.len() - 1 {
            mesh.triangles.push([resolved[0], resolved[k], resolved[k + 1]]);
        }
    }
    Ok(mesh)
}

/// Writes `v` lines (one per vertex, in order) then `f` lines (1-based).
pub fn write_obj(mut out: impl Write, positions: &[Vec3], triangles: &[[u32; 3]]) -> std::io::Result<()> {
    if let Some(v) = positions.iter().position(|p| !p.is_finite()) {
        return Err(std::io::Error::new(
            std::io::ErrorKind::InvalidData,
            format!("vertex {} is at {}, not a finite point: nothing was written", v + 1, positions[v]),
        ));
    }
    for p in positions {
        writeln!(out, "v {} {} {}", p.x, p.y, p.z)?;
    }
    for t in triangles {
        writeln!(out, "f {} {} {}", t[0] + 1, t[1] + 1, t[2] + 1)?;
    }
    Ok(())
}
