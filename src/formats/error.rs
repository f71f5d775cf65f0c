//! Errors of every reader: they say which file, which line and what was expected.

use std::fmt;
use std::path::{Path, PathBuf};

use crate::rig::RigError;

/// A reader's failure.
#[derive(Debug, thiserror::Error)]
pub enum FormatError {
    /// `path:line[:column]: message` — the input is not what the format expects.
    #[error("{}:{line}{}: {message}", path.display(), column.map(|c| format!(":{c}")).unwrap_or_default())]
    Syntax { path: PathBuf, line: usize, column: Option<usize>, message: String },
    /// The file parsed, but the rig it describes is invalid.
    // The cause is part of the message (not an error `source`), so chains print it once.
    #[error("{}: {cause}", path.display())]
    Rig { path: PathBuf, cause: RigError },
    /// The file could not be read or written.
    #[error("{}: {cause}", path.display())]
    Io { path: PathBuf, cause: std::io::Error },
    /// Something else about the file (missing companion files, unknown kind).
    #[error("{}: {message}", path.display())]
    Other { path: PathBuf, message: String },
}

impl FormatError {
    pub fn syntax(path: &Path, line: usize, message: impl fmt::Display) -> Self {
        Self::Syntax { path: path.to_path_buf(), line, column: None, message: message.to_string() }
    }

    /// As [`syntax`](Self::syntax), at a column of the line (counted from 1).
    pub fn syntax_at(path: &Path, line: usize, column: usize, message: impl fmt::Display) -> Self {
        Self::Syntax { path: path.to_path_buf(), line, column: Some(column), message: message.to_string() }
    }

    pub fn rig(path: &Path, source: RigError) -> Self {
        Self::Rig { path: path.to_path_buf(), cause: source }
    }

    pub fn io(path: &Path, source: std::io::Error) -> Self {
        Self::Io { path: path.to_path_buf(), cause: source }
    }

    pub fn other(path: &Path, message: impl fmt::Display) -> Self {
        Self::Other { path: path.to_path_buf(), message: message.to_string() }
    }
}

/// Opens a file for buffered reading, with the path in the error.
pub fn open(path: &Path) -> Result<std::io::BufReader<std::fs::File>, FormatError> {
    std::fs::File::open(path).map(std::io::BufReader::new).map_err(|e| FormatError::io(path, e))
}

/// Reads the whole input as UTF-8 text; bytes that are not UTF-8 are an error at their line.
pub fn read_text(mut reader: impl std::io::BufRead, path: &Path) -> Result<String, FormatError> {
    let mut bytes = Vec::new();
    reader.read_to_end(&mut bytes).map_err(|e| FormatError::io(path, e))?;
    String::from_utf8(bytes).map_err(|e| {
        let bytes = e.as_bytes();
        let at = e.utf8_error().valid_up_to();
        let line = 1 + bytes[..at].iter().filter(|&&b| b == b'\n').count();
        FormatError::syntax(path, line, format!("expected UTF-8 text, found the byte 0x{:02x}", bytes[at]))
    })
}

/// Reads lines (LF, CRLF, or bare CR line ends), numbered from 1, with the path in errors.
pub fn read_lines(reader: impl std::io::BufRead, path: &Path) -> Result<Vec<(usize, String)>, FormatError> {
    let text = read_text(reader, path)?;
    let text = text.replace("\r\n", "\n").replace('\r', "\n");
    Ok(text.lines().enumerate().map(|(i, l)| (i + 1, l.to_string())).collect())
}

/// A number a file may hold: integers, and floats that must be finite.
pub trait FileNumber: std::str::FromStr {
    /// Whether the value can be used (a float is finite; an integer always is).
    fn is_usable(&self) -> bool {
        true
    }
}

impl FileNumber for f32 {
    fn is_usable(&self) -> bool {
        self.is_finite()
    }
}

impl FileNumber for f64 {
    fn is_usable(&self) -> bool {
        self.is_finite()
    }
}

impl FileNumber for usize {}
impl FileNumber for u32 {}
impl FileNumber for i64 {}

/// One number, or `path:line: expected a number, found "tok"`; a float must be finite
/// (`expected a finite number, found nan`: NaN or infinity would poison every matrix).
pub fn parse_number<T: FileNumber>(token: &str, path: &Path, line_no: usize) -> Result<T, FormatError> {
    match token.parse::<T>() {
        Ok(v) if v.is_usable() => Ok(v),
        Ok(_) => Err(FormatError::syntax(path, line_no, format!("expected a finite number, found `{token}`"))),
        Err(_) => Err(FormatError::syntax(path, line_no, format!("expected a number, found `{token}`"))),
    }
}
