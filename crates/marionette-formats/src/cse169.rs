//! UCSD CSE169 `.skel`: nested `balljoint name { offset boxmin boxmax rotxlimit
//! rotylimit rotzlimit pose balljoint... }` blocks.

use std::io::BufRead;
use std::path::Path;

use glam::Vec3;

use super::error::FormatError;
use super::limits::MAX_TOKENS;
use marionette_rig::{BoneBox, DofLimits, JointRotation, MAX_JOINTS, RawJoint, Skeleton};

/// A token and the line it starts on.
#[derive(Debug, Clone, PartialEq)]
pub struct Token {
    pub text: String,
    pub line: usize,
}

/// Splits text into whitespace-separated tokens with their line numbers. LF, CRLF and bare
/// CR all end a line; `{` and `}` are tokens of their own even when glued to a word.
pub fn tokenize(reader: impl BufRead, path: &Path) -> Result<Vec<Token>, FormatError> {
    let bytes = super::error::read_all(reader, path)?;
    let text = String::from_utf8_lossy(&bytes);
    let mut tokens = Vec::new();
    let mut line = 1;
    let mut current = String::new();
    let mut start_line = 1;
    let mut prev_cr = false;
    let flush = |current: &mut String, tokens: &mut Vec<Token>, at: usize| {
        if !current.is_empty() {
            tokens.push(Token { text: std::mem::take(current), line: at });
        }
    };
    for c in text.chars() {
        if tokens.len() >= MAX_TOKENS {
            return Err(FormatError::syntax(
                path,
                line,
                format!("expected at most {MAX_TOKENS} words and braces, found more"),
            ));
        }
        match c {
            '\n' | '\r' => {
                flush(&mut current, &mut tokens, start_line);
                // "\r\n" is one line end.
                if !(c == '\n' && prev_cr) {
                    line += 1;
                }
            }
            '{' | '}' => {
                flush(&mut current, &mut tokens, start_line);
                tokens.push(Token { text: c.to_string(), line });
            }
            c if c.is_whitespace() => flush(&mut current, &mut tokens, start_line),
            c => {
                if current.is_empty() {
                    start_line = line;
                }
                current.push(c);
            }
        }
        prev_cr = c == '\r';
    }
    flush(&mut current, &mut tokens, start_line);
    Ok(tokens)
}

/// A cursor over tokens that reports `path:line: expected X, found Y`.
pub struct Tokens<'a> {
    tokens: Vec<Token>,
    pos: usize,
    path: &'a Path,
}

impl<'a> Tokens<'a> {
    pub fn new(tokens: Vec<Token>, path: &'a Path) -> Self {
        Self { tokens, pos: 0, path }
    }

    pub fn path(&self) -> &Path {
        self.path
    }

    pub fn peek(&self) -> Option<&Token> {
        self.tokens.get(self.pos)
    }

    /// The line of the next token (or of the last one at the end).
    pub fn line(&self) -> usize {
        self.tokens.get(self.pos).or(self.tokens.last()).map_or(1, |t| t.line)
    }

    pub fn error(&self, expected: &str) -> FormatError {
        let found =
            self.peek().map_or("the end of the file".to_string(), |t| format!("`{}`", super::error::excerpt(&t.text)));
        FormatError::syntax(self.path, self.line(), format!("expected {expected}, found {found}"))
    }

    pub fn next_token(&mut self, expected: &str) -> Result<Token, FormatError> {
        let t = self.peek().cloned().ok_or_else(|| self.error(expected))?;
        self.pos += 1;
        Ok(t)
    }

    pub fn expect(&mut self, word: &str) -> Result<(), FormatError> {
        match self.peek() {
            Some(t) if t.text == word => {
                self.pos += 1;
                Ok(())
            }
            _ => Err(self.error(&format!("`{word}`"))),
        }
    }

    pub fn number(&mut self, what: &str) -> Result<f32, FormatError> {
        match self.peek().map(|t| t.text.parse::<f32>()) {
            Some(Ok(v)) if v.is_finite() => {
                self.pos += 1;
                Ok(v)
            }
            Some(Ok(_)) => Err(self.error(&format!("a finite number ({what})"))),
            _ => Err(self.error(&format!("a number ({what})"))),
        }
    }

    pub fn vec3(&mut self, what: &str) -> Result<Vec3, FormatError> {
        Ok(Vec3::new(
            self.number(&format!("{what} x"))?,
            self.number(&format!("{what} y"))?,
            self.number(&format!("{what} z"))?,
        ))
    }

    pub fn at_end(&self) -> bool {
        self.pos >= self.tokens.len()
    }
}

/// Parses a CSE169 `.skel`. Joints are numbered depth-first in file order (the order
/// `.skin` files use). Defaults: offset 0, box ±0.1, unlimited rotation, pose 0. The pose
/// is clamped to the limits. Nesting is followed with an explicit stack (no recursion), so
/// any depth parses.
pub fn parse_skel(reader: impl BufRead, path: &Path) -> Result<Skeleton, FormatError> {
    let mut tokens = Tokens::new(tokenize(reader, path)?, path);
    if tokens.at_end() {
        return Err(tokens.error("`balljoint`"));
    }
    let mut raw: Vec<RawJoint> = Vec::new();
    // The joints whose `{` is open, innermost last.
    let mut open: Vec<OpenJoint> = vec![open_balljoint(&mut tokens, None, &mut raw)?];
    while let Some(current) = open.last_mut() {
        let keyword = tokens.peek().map(|t| t.text.clone());
        match keyword.as_deref() {
            Some("}") => {
                tokens.pos += 1;
                let done = open.pop().expect("the loop holds an open joint");
                close_balljoint(done, &mut raw);
                if open.is_empty() && !tokens.at_end() {
                    return Err(tokens.error("the end of the file after the root joint (one root per skeleton)"));
                }
            }
            Some("offset") => {
                tokens.pos += 1;
                current.joint.rest_offset = tokens.vec3("offset")?;
            }
            Some("boxmin") => {
                tokens.pos += 1;
                current.bone_box.min = tokens.vec3("boxmin")?;
            }
            Some("boxmax") => {
                tokens.pos += 1;
                current.bone_box.max = tokens.vec3("boxmax")?;
            }
            Some(k @ ("rotxlimit" | "rotylimit" | "rotzlimit")) => {
                let axis = usize::from(k.as_bytes()[3] - b'x');
                tokens.pos += 1;
                current.limits.min[axis] = tokens.number(&format!("{k} min"))?;
                current.limits.max[axis] = tokens.number(&format!("{k} max"))?;
            }
            Some("pose") => {
                tokens.pos += 1;
                current.pose = tokens.vec3("pose")?;
            }
            Some("balljoint") => {
                let parent = current.index;
                if raw.len() >= MAX_JOINTS {
                    return Err(tokens.error(&format!("at most {MAX_JOINTS} joints")));
                }
                let child = open_balljoint(&mut tokens, Some(parent), &mut raw)?;
                open.push(child);
            }
            _ => {
                return Err(
                    tokens.error("offset, boxmin, boxmax, rotxlimit, rotylimit, rotzlimit, pose, balljoint or `}`")
                );
            }
        }
    }
    Skeleton::build(raw).map_err(|e| FormatError::rig(path, e))
}

/// A joint whose block is being read.
struct OpenJoint {
    index: usize,
    joint: RawJoint,
    bone_box: BoneBox,
    limits: DofLimits,
    pose: Vec3,
}

/// Reads `balljoint NAME {`, reserves the joint's index (depth-first order) and opens it.
fn open_balljoint(
    tokens: &mut Tokens,
    parent: Option<usize>,
    raw: &mut Vec<RawJoint>,
) -> Result<OpenJoint, FormatError> {
    tokens.expect("balljoint")?;
    let name = tokens.next_token("a joint name")?;
    if name.text == "{" || name.text == "}" {
        tokens.pos -= 1;
        return Err(tokens.error("a joint name"));
    }
    tokens.expect("{")?;
    let joint = RawJoint::new(name.text, parent, Vec3::ZERO);
    raw.push(joint.clone());
    Ok(OpenJoint {
        index: raw.len() - 1,
        joint,
        bone_box: BoneBox { min: Vec3::splat(-0.1), max: Vec3::splat(0.1) },
        limits: DofLimits::UNLIMITED,
        pose: Vec3::ZERO,
    })
}

/// Stores a joint whose `}` was read.
fn close_balljoint(done: OpenJoint, raw: &mut [RawJoint]) {
    let OpenJoint { index, mut joint, bone_box, limits, pose } = done;
    joint.limits = limits;
    joint.bone_box = Some(bone_box);
    joint.initial_rotation = JointRotation::euler_xyz(pose.x, pose.y, pose.z);
    raw[index] = joint;
}
