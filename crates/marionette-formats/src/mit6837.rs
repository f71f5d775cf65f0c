//! MIT 6.837 assignment 2: `.skel` (`x y z parent` per line) and `.attach` weights.

use std::io::BufRead;
use std::path::Path;

use glam::Vec3;

use super::error::{FormatError, parse_number, read_lines};
use marionette_rig::skinning::NormalisedRow;
use marionette_rig::{MAX_JOINTS, RawJoint, Skeleton, SkinWeights};

/// Parses a 6.837 `.skel`: one joint per line, `x y z parent`; the root (parent -1) is
/// absolute, the others are offsets from their parent. Blank lines are skipped.
/// Joints are named `joint0`, `joint1`, ... since the course files have no names; as our
/// extension, an optional fifth token names the joint (`x y z parent name`).
pub fn parse_skel(reader: impl BufRead, path: &Path) -> Result<Skeleton, FormatError> {
    let mut raw = Vec::new();
    for (line_no, line) in read_lines(reader, path)? {
        if line.trim().is_empty() {
            continue;
        }
        let tokens: Vec<&str> = line.split_whitespace().collect();
        if !(4..=5).contains(&tokens.len()) {
            return Err(FormatError::syntax(
                path,
                line_no,
                format!("expected 4 numbers (x y z parent), found {}", tokens.len()),
            ));
        }
        let xyz = tokens[..3].iter().map(|t| parse_number::<f32>(t, path, line_no)).collect::<Result<Vec<_>, _>>()?;
        let parent: i64 = tokens[3].parse().map_err(|_| {
            FormatError::syntax(
                path,
                line_no,
                format!("expected an integer parent index, found `{}`", super::error::excerpt(tokens[3])),
            )
        })?;
        let index = raw.len();
        if index == MAX_JOINTS {
            return Err(FormatError::syntax(
                path,
                line_no,
                format!("expected at most {MAX_JOINTS} joints, found more"),
            ));
        }
        let parent = match parent {
            -1 if index > 0 => {
                return Err(FormatError::syntax(
                    path,
                    line_no,
                    format!("joint {index} is a second root (parent -1); expected a parent index in 0..{index}"),
                ));
            }
            -1 => None,
            p if p < 0 || p as usize >= index => {
                let what = if p >= 0 && (p as usize) == index { "itself" } else { "a joint not defined before it" };
                return Err(FormatError::syntax(
                    path,
                    line_no,
                    format!("parent index {p} of joint {index} refers to {what} (expected -1 or 0..{index})"),
                ));
            }
            p => Some(p as usize),
        };
        let name = tokens.get(4).map_or_else(|| format!("joint{index}"), |n| n.to_string());
        raw.push(RawJoint::new(name, parent, Vec3::new(xyz[0], xyz[1], xyz[2])));
    }
    if raw.is_empty() {
        return Err(FormatError::syntax(path, 1, "expected at least one joint line `x y z parent`, found none"));
    }
    Skeleton::build(raw).map_err(|e| FormatError::rig(path, e))
}

/// Parses a 6.837 `.attach`: one line per mesh vertex with one weight per joint except
/// the root (column k is joint k + 1). Rows that do not sum to 1 are normalised and
/// returned as warnings; a row of the wrong width or a count that differs from
/// `vertex_count` is an error.
pub fn parse_attach(
    reader: impl BufRead,
    path: &Path,
    joint_count: usize,
    vertex_count: usize,
) -> Result<(SkinWeights, Vec<NormalisedRow>), FormatError> {
    let columns = joint_count.saturating_sub(1);
    let mut rows = Vec::with_capacity(vertex_count);
    let mut last_line = 0;
    let mut row_width: Option<usize> = None;
    for (line_no, line) in read_lines(reader, path)? {
        last_line = line_no;
        if line.trim().is_empty() {
            continue;
        }
        if rows.len() == vertex_count {
            return Err(FormatError::syntax(
                path,
                line_no,
                format!("expected {vertex_count} weight lines (one per mesh vertex), found more"),
            ));
        }
        let found = line.split_whitespace().count();
        // Our extension: a file may carry a root column too (one weight per joint),
        // consistently on every line.
        let width =
            *row_width.get_or_insert(if found == joint_count && joint_count > 1 { joint_count } else { columns });
        if found != width {
            return Err(FormatError::syntax(
                path,
                line_no,
                format!(
                    "expected {width} weights (one per joint{}), found {found}",
                    if width == columns { " except the root" } else { "" }
                ),
            ));
        }
        let weights =
            line.split_whitespace().map(|t| parse_number::<f32>(t, path, line_no)).collect::<Result<Vec<_>, _>>()?;
        if let Some(w) = weights.iter().find(|w| **w < 0.0 || !w.is_finite()) {
            return Err(FormatError::syntax(path, line_no, format!("expected weights >= 0, found {w}")));
        }
        if weights.iter().all(|&w| w <= 0.0) {
            return Err(FormatError::syntax(path, line_no, "expected at least one positive weight, found none"));
        }
        rows.push(weights);
    }
    if rows.len() != vertex_count {
        return Err(FormatError::syntax(
            path,
            last_line.max(1),
            format!("expected {vertex_count} weight lines (one per mesh vertex), found {}", rows.len()),
        ));
    }
    let sparse = rows.iter().map(|r| r.iter().enumerate().map(|(k, &w)| (k + 1, w)));
    SkinWeights::from_rows(sparse, joint_count).map_err(|e| FormatError::rig(path, e))
}

/// Writes weights in the 6.837 `.attach` layout: one column per joint except the root;
/// when some vertex is weighted to the root, every line gets a leading root column instead
/// (our extension, read back by [`parse_attach`]).
pub fn write_attach(mut out: impl std::io::Write, weights: &SkinWeights, joint_count: usize) -> std::io::Result<()> {
    let root_used = (0..weights.vertex_count()).any(|v| weights.weight(v, 0) > 0.0);
    let first = if root_used || joint_count < 2 { 0 } else { 1 };
    let mut row = vec![0.0f32; joint_count];
    for v in 0..weights.vertex_count() {
        row.fill(0.0);
        for inf in weights.of_vertex(v) {
            row[inf.joint as usize] += inf.weight;
        }
        let line: Vec<String> = row[first..].iter().map(|&w| format_weight(w)).collect();
        writeln!(out, "{}", line.join(" "))?;
    }
    Ok(())
}

/// A weight with up to 6 decimals and no trailing zeros (`0`, `0.25`, `0.333333`).
fn format_weight(w: f32) -> String {
    if w == 0.0 {
        return "0".to_string();
    }
    let s = format!("{w:.6}");
    s.trim_end_matches('0').trim_end_matches('.').to_string()
}
