//! Scene-input errors and warnings, each with the `file:line:column` it refers to.

use std::fmt;
use std::path::PathBuf;
use std::sync::Arc;

/// A position in a scene file: 1-based line and column.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct FileLoc {
    pub file: Arc<str>,
    pub line: u32,
    pub column: u32,
}

impl FileLoc {
    pub fn new(file: impl Into<Arc<str>>, line: u32, column: u32) -> FileLoc {
        FileLoc {
            file: file.into(),
            line,
            column,
        }
    }

    /// A location for objects built in code (the canonical scenes).
    pub fn builtin(name: &str) -> FileLoc {
        FileLoc::new(format!("<builtin:{name}>"), 0, 0)
    }
}

impl fmt::Display for FileLoc {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        // Line 0 marks a place that is not in a file (a built-in scene, a command-line
        // flag): its name alone, not a made-up position.
        if self.line == 0 {
            write!(f, "{}", self.file)
        } else {
            write!(f, "{}:{}:{}", self.file, self.line, self.column)
        }
    }
}

/// An error in scene input. Every variant names where it happened.
#[derive(Debug, thiserror::Error)]
pub enum SceneError {
    /// A problem at a position in a scene (or included) file.
    #[error("{loc}: error: {message}")]
    At { loc: FileLoc, message: String },
    /// A file that could not be read (scene, Include, PLY/OBJ mesh, lens file).
    #[error("{}: error: {message}", path.display())]
    File { path: PathBuf, message: String },
}

impl SceneError {
    pub fn at(loc: &FileLoc, message: impl Into<String>) -> SceneError {
        SceneError::At {
            loc: loc.clone(),
            message: message.into(),
        }
    }

    pub fn file(path: impl Into<PathBuf>, message: impl Into<String>) -> SceneError {
        SceneError::File {
            path: path.into(),
            message: message.into(),
        }
    }
}

/// A warning about scene input: something read but not supported, a parameter that was
/// never used. Warnings never stop a render, but they are always shown.
#[derive(Clone, Debug, PartialEq)]
pub struct Warning {
    pub loc: FileLoc,
    pub message: String,
}

impl fmt::Display for Warning {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}: warning: {}", self.loc, self.message)
    }
}
