//! UCSD CSE169 `.skin`, `.morph` and `.anim` files, read with the `.skel` tokenizer (LF,
//! CRLF and CR-only lines, braces glued to words).
//!
//! `.skin`: `positions N {x y z …}`, `normals N {…}`, optional `texcoords N {u v …}`,
//! `skinweights N {count joint weight …}`, optional `material name {texture file}`,
//! `triangles N {a b c …}`, `bindings N {matrix {a; b; c; d}}` — each joint's world bind
//! matrix by its columns a, b, c (axes) and d (position), four rows of three numbers.
//!
//! `.morph`: `positions N {index x y z …}` and `normals N {index x y z …}`: where the named
//! vertices go in the morph target (absolute, as the files hold them: `head1.morph` gives
//! vertex 18 at (0.077, 0.222, −0.595), `head.skin` has it at (0.0772, 0.2225, −0.5949)).
//!
//! `.anim`: `animation { range t0 t1  numchannels N  channel [k] { extrapolate IN OUT
//! keys K { time value tanIn tanOut … } } … }`. Besides CSE169's tangents (`flat`,
//! `linear`, `smooth`, a number) ours read and write `step`: hold until the next key.

use std::io::BufRead;
use std::path::{Path, PathBuf};

use glam::{Mat4, Vec2, Vec3, Vec4};

use super::cse169::{Tokens, tokenize};
use super::error::FormatError;
use marionette_rig::anim::{Channel, Clip, Extrapolation, Key, Tangent};

/// What a `.skin` file holds.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct SkinFile {
    pub positions: Vec<Vec3>,
    pub normals: Vec<Vec3>,
    pub texcoords: Vec<Vec2>,
    /// Per vertex, its (joint, weight) pairs as written.
    pub weights: Vec<Vec<(usize, f32)>>,
    pub triangles: Vec<[u32; 3]>,
    /// Each joint's world bind matrix.
    pub bindings: Vec<Mat4>,
    /// The texture named by `material`, resolved beside the file.
    pub texture: Option<PathBuf>,
}

/// A count, then `{`.
fn counted_block(tokens: &mut Tokens, what: &str) -> Result<usize, FormatError> {
    let line = tokens.line();
    let n = tokens.number(&format!("the number of {what}"))?;
    if n < 0.0 || n.fract() != 0.0 || n > 1e8 {
        return Err(FormatError::syntax(tokens.path(), line, format!("expected a count of {what}, found {n}")));
    }
    tokens.expect("{")?;
    Ok(n as usize)
}

/// A whole number in `0..below` (an index into something of that size).
fn index(tokens: &mut Tokens, what: &str, below: usize) -> Result<usize, FormatError> {
    let line = tokens.line();
    let v = tokens.number(what)?;
    if v < 0.0 || v.fract() != 0.0 || v >= below as f32 {
        return Err(FormatError::syntax(
            tokens.path(),
            line,
            format!("expected {what} (a whole number below {below}), found {v}"),
        ));
    }
    Ok(v as usize)
}

/// Parses a `.skin`. Vertex indices are checked against `positions`; joint indices are
/// checked where the skin meets its skeleton.
pub fn parse_skin(reader: impl BufRead, path: &Path) -> Result<SkinFile, FormatError> {
    let mut tokens = Tokens::new(tokenize(reader, path)?, path);
    let mut skin = SkinFile::default();
    while let Some(word) = tokens.peek().map(|t| t.text.clone()) {
        tokens.next_token("a section")?;
        match word.as_str() {
            "positions" => skin.positions = vec3_block(&mut tokens, "positions")?,
            "normals" => skin.normals = vec3_block(&mut tokens, "normals")?,
            "texcoords" => {
                let n = counted_block(&mut tokens, "texcoords")?;
                skin.texcoords = (0..n)
                    .map(|_| Ok(Vec2::new(tokens.number("texcoord u")?, tokens.number("texcoord v")?)))
                    .collect::<Result<_, FormatError>>()?;
                tokens.expect("}")?;
            }
            "skinweights" => {
                let n = counted_block(&mut tokens, "skinweights")?;
                skin.weights = (0..n)
                    .map(|_| {
                        let count = index(&mut tokens, "the number of weights", 1 << 16)?;
                        (0..count)
                            .map(|_| Ok((index(&mut tokens, "a joint", 1 << 16)?, tokens.number("a weight")?)))
                            .collect::<Result<Vec<_>, FormatError>>()
                    })
                    .collect::<Result<_, FormatError>>()?;
                tokens.expect("}")?;
            }
            "material" => {
                tokens.next_token("the material's name")?;
                tokens.expect("{")?;
                while tokens.peek().is_some_and(|t| t.text != "}") {
                    let key = tokens.next_token("`texture`")?;
                    let value = tokens.next_token("a file name")?;
                    if key.text == "texture" {
                        let texture = super::uri::inside_folder(path, &value.text)
                            .map_err(|e| FormatError::syntax(path, value.line, e))?;
                        skin.texture = Some(texture);
                    }
                }
                tokens.expect("}")?;
            }
            "triangles" => {
                let n = counted_block(&mut tokens, "triangles")?;
                let count = skin.positions.len();
                skin.triangles = (0..n)
                    .map(|_| {
                        let mut t = [0u32; 3];
                        for c in &mut t {
                            *c = index(&mut tokens, "a vertex index", count)? as u32;
                        }
                        Ok(t)
                    })
                    .collect::<Result<_, FormatError>>()?;
                tokens.expect("}")?;
            }
            "bindings" => {
                let n = counted_block(&mut tokens, "bindings")?;
                skin.bindings = (0..n).map(|_| binding(&mut tokens)).collect::<Result<_, FormatError>>()?;
                tokens.expect("}")?;
            }
            other => {
                return Err(FormatError::syntax(
                    path,
                    tokens.line(),
                    format!(
                        "expected `positions`, `normals`, `texcoords`, `skinweights`, `material`, `triangles` or `bindings`, found `{}`",
                        super::error::excerpt(other)
                    ),
                ));
            }
        }
    }
    if skin.weights.len() != skin.positions.len() {
        return Err(FormatError::syntax(
            path,
            tokens.line(),
            format!(
                "expected skinweights for each of the {} positions by the end of the file, found {}",
                skin.positions.len(),
                skin.weights.len()
            ),
        ));
    }
    Ok(skin)
}

fn vec3_block(tokens: &mut Tokens, what: &str) -> Result<Vec<Vec3>, FormatError> {
    let n = counted_block(tokens, what)?;
    let v = (0..n).map(|_| tokens.vec3(what)).collect::<Result<_, _>>()?;
    tokens.expect("}")?;
    Ok(v)
}

/// `matrix { a b c d }`: columns a, b, c and the position d, three numbers each.
fn binding(tokens: &mut Tokens) -> Result<Mat4, FormatError> {
    tokens.expect("matrix")?;
    tokens.expect("{")?;
    let [a, b, c, d] = [0, 1, 2, 3].map(|_| tokens.vec3("a binding matrix row"));
    tokens.expect("}")?;
    Ok(Mat4::from_cols(a?.extend(0.0), b?.extend(0.0), c?.extend(0.0), Vec4::from((d?, 1.0))))
}

/// A `.morph` target: the vertices it moves and where they go, and their normals.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct MorphFile {
    pub positions: Vec<(usize, Vec3)>,
    pub normals: Vec<(usize, Vec3)>,
}

/// Parses a `.morph` for a skin of `vertex_count` vertices.
pub fn parse_morph(reader: impl BufRead, path: &Path, vertex_count: usize) -> Result<MorphFile, FormatError> {
    let mut tokens = Tokens::new(tokenize(reader, path)?, path);
    let mut morph = MorphFile::default();
    while let Some(word) = tokens.peek().map(|t| t.text.clone()) {
        tokens.next_token("a section")?;
        let list = match word.as_str() {
            "positions" => &mut morph.positions,
            "normals" => &mut morph.normals,
            other => {
                return Err(FormatError::syntax(
                    path,
                    tokens.line(),
                    format!("expected `positions` or `normals`, found `{}`", super::error::excerpt(other)),
                ));
            }
        };
        let n = counted_block(&mut tokens, &word)?;
        for _ in 0..n {
            let v = index(&mut tokens, "a vertex index", vertex_count)?;
            list.push((v, tokens.vec3(&word)?));
        }
        tokens.expect("}")?;
    }
    Ok(morph)
}

/// Parses a `.anim` clip.
pub fn parse_anim(reader: impl BufRead, path: &Path) -> Result<Clip, FormatError> {
    let mut tokens = Tokens::new(tokenize(reader, path)?, path);
    tokens.expect("animation")?;
    tokens.expect("{")?;
    tokens.expect("range")?;
    let range = (tokens.number("the range's start")?, tokens.number("the range's end")?);
    tokens.expect("numchannels")?;
    let count = index(&mut tokens, "the number of channels", 1 << 20)?;
    if !(range.1 - range.0).is_finite() {
        return Err(FormatError::syntax(path, tokens.line(), "expected a range whose length is finite"));
    }
    let channels = (0..count).map(|_| channel(&mut tokens)).collect::<Result<_, _>>()?;
    tokens.expect("}")?;
    if !tokens.at_end() {
        return Err(tokens.error("the end of the file after the animation"));
    }
    Ok(Clip { range, channels, joint_names: Vec::new(), offsets: Vec::new() })
}

fn channel(tokens: &mut Tokens) -> Result<Channel, FormatError> {
    tokens.expect("channel")?;
    // Newer files number their channels (`channel 14 {`).
    if tokens.peek().is_some_and(|t| t.text != "{") {
        tokens.number("the channel's number")?;
    }
    tokens.expect("{")?;
    tokens.expect("extrapolate")?;
    let before = extrapolation(tokens)?;
    let after = extrapolation(tokens)?;
    tokens.expect("keys")?;
    let n = counted_block(tokens, "keys")?;
    let mut lines = Vec::new();
    let keys = (0..n)
        .map(|_| {
            lines.push(tokens.line());
            Ok(Key {
                time: tokens.number("a key's time")?,
                value: tokens.number("a key's value")?,
                tangent_in: tangent(tokens)?,
                tangent_out: tangent(tokens)?,
            })
        })
        .collect::<Result<Vec<_>, FormatError>>()?;
    tokens.expect("}")?;
    tokens.expect("}")?;
    // The channel sorts its keys by time (stably): the lines in the same order.
    let mut by_time: Vec<(f32, usize)> = keys.iter().map(|k| k.time).zip(lines).collect();
    by_time.sort_by(|a, b| a.0.total_cmp(&b.0));
    let channel = Channel::new(keys, before, after);
    if let Some(k) = channel.first_unusable_key() {
        return Err(FormatError::syntax(
            tokens.path(),
            by_time[k].1,
            "expected a key whose curve stays finite (its value or slope overflows)",
        ));
    }
    Ok(channel)
}

fn extrapolation(tokens: &mut Tokens) -> Result<Extrapolation, FormatError> {
    let mode = match tokens.peek().map(|t| t.text.as_str()) {
        Some("constant") => Extrapolation::Constant,
        Some("linear") => Extrapolation::Linear,
        Some("cycle") => Extrapolation::Cycle,
        Some("cycle_offset") => Extrapolation::CycleOffset,
        Some("bounce") => Extrapolation::Bounce,
        _ => return Err(tokens.error("an extrapolation (constant, linear, cycle, cycle_offset, bounce)")),
    };
    tokens.next_token("an extrapolation")?;
    Ok(mode)
}

fn tangent(tokens: &mut Tokens) -> Result<Tangent, FormatError> {
    let rule = match tokens.peek().map(|t| t.text.as_str()) {
        Some("flat") => Tangent::Flat,
        Some("step") => Tangent::Step,
        Some("linear") => Tangent::Linear,
        Some("smooth") => Tangent::Smooth,
        _ => return Ok(Tangent::Fixed(tokens.number("a tangent (flat, linear, smooth or a number)")?)),
    };
    tokens.next_token("a tangent")?;
    Ok(rule)
}

/// Writes `clip` as a `.anim` (numbers as Rust prints them, which read back exactly).
pub fn write_anim(w: &mut impl std::io::Write, clip: &Clip) -> std::io::Result<()> {
    let extrapolation = |e: Extrapolation| match e {
        Extrapolation::Constant => "constant",
        Extrapolation::Linear => "linear",
        Extrapolation::Cycle => "cycle",
        Extrapolation::CycleOffset => "cycle_offset",
        Extrapolation::Bounce => "bounce",
    };
    let tangent = |t: Tangent| match t {
        Tangent::Flat => "flat".to_string(),
        Tangent::Step => "step".to_string(),
        Tangent::Linear => "linear".to_string(),
        Tangent::Smooth => "smooth".to_string(),
        Tangent::Fixed(s) => format!("{s:?}"),
    };
    writeln!(w, "animation {{")?;
    writeln!(w, "  range {:?} {:?}", clip.range.0, clip.range.1)?;
    writeln!(w, "  numchannels {}", clip.channels.len())?;
    for (i, c) in clip.channels.iter().enumerate() {
        writeln!(w, "  channel {i} {{")?;
        writeln!(w, "    extrapolate {} {}", extrapolation(c.before), extrapolation(c.after))?;
        writeln!(w, "    keys {} {{", c.keys().len())?;
        for k in c.keys() {
            writeln!(w, "      {:?} {:?} {} {}", k.time, k.value, tangent(k.tangent_in), tangent(k.tangent_out))?;
        }
        writeln!(w, "    }}")?;
        writeln!(w, "  }}")?;
    }
    writeln!(w, "}}")
}
