//! JSON inputs (scenarios, column maps, identification manifests) read with the JSON path of
//! every error.

use std::path::Path;

use crate::error::{IoAction, IoError, Result};

/// Reads the JSON file `path` into `T`.
///
/// # Errors
/// [`IoError::Io`] if it cannot be read, else as [`parse_json`].
pub fn parse_json_file<T: serde::de::DeserializeOwned>(path: &Path) -> Result<T> {
    let text = std::fs::read_to_string(path).map_err(|source| IoError::Io {
        path: path.to_owned(),
        action: IoAction::Reading,
        source,
    })?;
    parse_json(path, &text)
}

/// Parses JSON text read from `path` into `T`, reporting the JSON path (or line and
/// column) of any error: for scenario files and the other JSON inputs of platen (column
/// maps, identification manifests).
///
/// # Errors
/// [`IoError::Json`].
pub fn parse_json<T: serde::de::DeserializeOwned>(path: &Path, text: &str) -> Result<T> {
    let de = &mut serde_json::Deserializer::from_str(text);
    serde_path_to_error::deserialize(de).map_err(|e| {
        let inner = e.inner();
        let json_path = e.path().to_string();
        let json_path = if json_path == "." || json_path.is_empty() {
            format!("line {} column {}", inner.line(), inner.column())
        } else {
            format!(
                "{json_path} (line {} column {})",
                inner.line(),
                inner.column()
            )
        };
        // serde_json appends " at line L column C"; the location is already in json_path.
        let mut message = inner.to_string();
        if let Some(pos) = message.rfind(" at line ") {
            message.truncate(pos);
        }
        IoError::Json {
            path: path.to_owned(),
            json_path,
            message,
        }
    })
}
