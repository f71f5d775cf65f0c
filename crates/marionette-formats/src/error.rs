//! Errors of every reader: they say which file, which line and what was expected.

use std::fmt;
use std::path::{Path, PathBuf};

use marionette_rig::RigError;

pub use super::limits::{MAX_EXCERPT_CHARS, MAX_FILE_BYTES, MAX_MESSAGE_CHARS};

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
        Self::Syntax { path: path.to_path_buf(), line, column: None, message: bounded(message) }
    }

    /// As [`syntax`](Self::syntax), at a column of the line (counted from 1).
    pub fn syntax_at(path: &Path, line: usize, column: usize, message: impl fmt::Display) -> Self {
        Self::Syntax { path: path.to_path_buf(), line, column: Some(column), message: bounded(message) }
    }

    pub fn rig(path: &Path, source: RigError) -> Self {
        Self::Rig { path: path.to_path_buf(), cause: source }
    }

    pub fn io(path: &Path, source: std::io::Error) -> Self {
        Self::Io { path: path.to_path_buf(), cause: source }
    }

    pub fn other(path: &Path, message: impl fmt::Display) -> Self {
        Self::Other { path: path.to_path_buf(), message: bounded(message) }
    }
}

/// A message cut to [`MAX_MESSAGE_CHARS`] characters: the last guard against quoting a
/// huge token (a RON parser's error names the identifier it found, whatever its length).
fn bounded(message: impl fmt::Display) -> String {
    cut_to(&message.to_string(), MAX_MESSAGE_CHARS).into_owned()
}

/// `text`, or its first `chars` characters and `…` where it is longer.
fn cut_to(text: &str, chars: usize) -> std::borrow::Cow<'_, str> {
    match text.char_indices().nth(chars) {
        None => text.into(),
        Some((cut, _)) => format!("{}…", &text[..cut]).into(),
    }
}

/// Opens a file for buffered reading, with the path in the error. Only a regular file of at
/// most [`MAX_FILE_BYTES`] is opened (see [`open_regular`]); reading stops past the limit.
pub fn open(path: &Path) -> Result<std::io::BufReader<std::io::Take<std::fs::File>>, FormatError> {
    use std::io::Read;
    Ok(std::io::BufReader::new(open_regular(path)?.take(MAX_FILE_BYTES + 1)))
}

/// A whole file's bytes: a regular file of at most [`MAX_FILE_BYTES`].
pub fn read_file(path: &Path) -> Result<Vec<u8>, FormatError> {
    read_all(open_regular(path)?, path)
}

/// Every byte of `reader`, or an error once it passes [`MAX_FILE_BYTES`] (reading stops
/// there).
pub fn read_all(reader: impl std::io::Read, path: &Path) -> Result<Vec<u8>, FormatError> {
    use std::io::Read;
    let mut bytes = Vec::new();
    reader.take(MAX_FILE_BYTES + 1).read_to_end(&mut bytes).map_err(|e| FormatError::io(path, e))?;
    within_limit(bytes.len() as u64, path)?;
    Ok(bytes)
}

/// Opens `path` for reading if it is a regular file no larger than [`MAX_FILE_BYTES`]:
/// a folder, a FIFO, a device or a socket is refused at once, without reading (a FIFO
/// would block, `/dev/zero` never end). The file is opened without blocking and checked
/// again, so a FIFO put in its place in between is refused too.
pub fn open_regular(path: &Path) -> Result<std::fs::File, FormatError> {
    regular_within_limit(&std::fs::metadata(path).map_err(|e| FormatError::io(path, e))?, path)?;
    let mut options = std::fs::OpenOptions::new();
    options.read(true);
    #[cfg(unix)]
    std::os::unix::fs::OpenOptionsExt::custom_flags(&mut options, libc::O_NONBLOCK);
    let file = options.open(path).map_err(|e| FormatError::io(path, e))?;
    regular_within_limit(&file.metadata().map_err(|e| FormatError::io(path, e))?, path)?;
    remember_read(path);
    Ok(file)
}

/// Every file this process opened for reading (their canonical paths), so a command can
/// refuse to write over one of its own inputs.
static FILES_READ: std::sync::Mutex<std::collections::BTreeSet<PathBuf>> =
    std::sync::Mutex::new(std::collections::BTreeSet::new());

fn remember_read(path: &Path) {
    if let (Ok(real), Ok(mut read)) = (path.canonicalize(), FILES_READ.lock()) {
        read.insert(real);
    }
}

/// Refuses `out` when it is a file this process has read (`export x.glb --out x.glb`, or
/// `--out` naming a skeleton's own `.obj`): writing would destroy an input.
pub fn refuse_overwriting_input(out: &Path) -> Result<(), FormatError> {
    let Ok(real) = out.canonicalize() else { return Ok(()) };
    if FILES_READ.lock().is_ok_and(|read| read.contains(&real)) {
        return Err(FormatError::other(
            out,
            "expected a new file to write, found a file this command read (an input is never overwritten)",
        ));
    }
    Ok(())
}

fn regular_within_limit(meta: &std::fs::Metadata, path: &Path) -> Result<(), FormatError> {
    if !meta.is_file() {
        let what = if meta.is_dir() { "a folder" } else { "a special file (a FIFO, device or socket)" };
        return Err(FormatError::other(path, format!("expected a regular file, found {what}")));
    }
    within_limit(meta.len(), path)
}

fn within_limit(len: u64, path: &Path) -> Result<(), FormatError> {
    if len > MAX_FILE_BYTES {
        return Err(FormatError::other(
            path,
            format!("the file is larger than the {} MiB Marionette reads (MAX_FILE_BYTES)", MAX_FILE_BYTES >> 20),
        ));
    }
    Ok(())
}

/// At most [`MAX_EXCERPT_CHARS`] characters of a token for an error message, with `…`
/// where it was cut (a malformed file's "token" may be gigabytes long).
pub fn excerpt(token: &str) -> std::borrow::Cow<'_, str> {
    cut_to(token, MAX_EXCERPT_CHARS)
}

/// Reads the whole input as UTF-8 text; bytes that are not UTF-8 are an error at their line.
/// Input beyond [`MAX_FILE_BYTES`] is refused.
pub fn read_text(reader: impl std::io::BufRead, path: &Path) -> Result<String, FormatError> {
    String::from_utf8(read_all(reader, path)?).map_err(|e| {
        let bytes = e.as_bytes();
        let at = e.utf8_error().valid_up_to();
        let line = 1 + bytes[..at].iter().filter(|&&b| b == b'\n').count();
        FormatError::syntax(path, line, format!("expected UTF-8 text, found the byte 0x{:02x}", bytes[at]))
    })
}

/// Reads lines (LF, CRLF, or bare CR line ends), numbered from 1, with the path in errors.
pub fn read_lines(reader: impl std::io::BufRead, path: &Path) -> Result<Vec<(usize, String)>, FormatError> {
    let mut lines = Lines::new(reader, path);
    let mut all = Vec::new();
    while let Some((n, line)) = lines.next_line()? {
        all.push((n, line.to_string()));
    }
    Ok(all)
}

/// A file's lines one at a time (LF, CRLF or bare CR line ends), numbered from 1, so a
/// reader holds one line, not the whole file. Reading stops with an error past
/// [`MAX_FILE_BYTES`]; a line that is not UTF-8 is an error at its number.
pub struct Lines<'p, R> {
    reader: R,
    path: &'p Path,
    line: usize,
    buf: Vec<u8>,
    /// The last line ended with a CR: a LF right after it belongs to that line end.
    after_cr: bool,
    read: u64,
}

impl<'p, R: std::io::BufRead> Lines<'p, R> {
    pub fn new(reader: R, path: &'p Path) -> Self {
        Self { reader, path, line: 0, buf: Vec::new(), after_cr: false, read: 0 }
    }

    /// The number of the line last returned (0 before the first).
    pub fn line(&self) -> usize {
        self.line
    }

    /// The next line and its number, or none at the end of the input.
    pub fn next_line(&mut self) -> Result<Option<(usize, &str)>, FormatError> {
        self.buf.clear();
        let mut ended = false;
        loop {
            let chunk = self.reader.fill_buf().map_err(|e| FormatError::io(self.path, e))?;
            if chunk.is_empty() {
                break;
            }
            let mut skip = 0;
            if self.after_cr && chunk[0] == b'\n' {
                skip = 1;
            }
            self.after_cr = false;
            let rest = &chunk[skip..];
            let used = match rest.iter().position(|&b| b == b'\n' || b == b'\r') {
                Some(at) => {
                    self.buf.extend_from_slice(&rest[..at]);
                    self.after_cr = rest[at] == b'\r';
                    ended = true;
                    skip + at + 1
                }
                None => {
                    self.buf.extend_from_slice(rest);
                    chunk.len()
                }
            };
            self.reader.consume(used);
            self.read += used as u64;
            within_limit(self.read, self.path)?;
            if ended {
                break;
            }
        }
        if !ended && self.buf.is_empty() {
            return Ok(None);
        }
        self.line += 1;
        let line = self.line;
        match std::str::from_utf8(&self.buf) {
            Ok(text) => Ok(Some((line, text))),
            Err(e) => Err(FormatError::syntax(
                self.path,
                line,
                format!("expected UTF-8 text, found the byte 0x{:02x}", self.buf[e.valid_up_to()]),
            )),
        }
    }
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
        Ok(_) => {
            Err(FormatError::syntax(path, line_no, format!("expected a finite number, found `{}`", excerpt(token))))
        }
        Err(_) => Err(FormatError::syntax(path, line_no, format!("expected a number, found `{}`", excerpt(token)))),
    }
}
