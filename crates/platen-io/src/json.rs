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
/// The path names the innermost field: where serde loses it (a field inside an internally
/// tagged or flattened object, reported at the object), the document is read a second time
/// as plain JSON and the one field under that object holding the value the message quotes
/// is named. A file that ends early (empty, or cut off) says so with the line it ends on.
///
/// # Errors
/// [`IoError::JsonSyntax`] for text that is not JSON (with the line and column), else
/// [`IoError::Json`].
pub fn parse_json<T: serde::de::DeserializeOwned>(path: &Path, text: &str) -> Result<T> {
    let de = &mut serde_json::Deserializer::from_str(text);
    serde_path_to_error::deserialize(de).map_err(|e| json_error(path, text, &e))
}

/// The error `e` of reading `text` (from `path`), as [`parse_json`] reports it.
fn json_error(
    path: &Path,
    text: &str,
    e: &serde_path_to_error::Error<serde_json::Error>,
) -> IoError {
    let inner = e.inner();
    let (line, column) = (inner.line(), inner.column());
    if inner.is_eof() {
        return early_end(path, text, line);
    }
    // serde_json appends " at line L column C"; the location is already in json_path.
    let mut message = inner.to_string();
    if let Some(pos) = message.rfind(" at line ") {
        message.truncate(pos);
    }
    // A syntax error has no field to name: serde_path_to_error's path there is where it
    // was reading (`?` for a key still to come), which means nothing to the reader.
    // serde_json reads a fixed-length array (`[f64; 3]`) element by element and reports the
    // elements left over as "trailing characters", a syntax error; in a document that is
    // valid JSON it is an array too long for its key, named at that key.
    if inner.is_syntax()
        && message == "trailing characters"
        && serde_json::from_str::<serde::de::IgnoredAny>(text).is_ok()
    {
        let json_path = e.path().to_string();
        return IoError::Json {
            path: path.to_owned(),
            json_path: format!("{json_path} (line {line} column {column})"),
            message: "an array with more elements than this key takes (a point or vector \
                      has three: x, y, z)"
                .to_owned(),
        };
    }
    if inner.is_syntax() {
        return IoError::JsonSyntax {
            path: path.to_owned(),
            line: line as u64,
            column: column as u64,
            message,
        };
    }
    if let Some(rest) = message.strip_suffix(", expected f64") {
        message = format!("{rest}, expected a number");
    }
    let json_path = data_path(e, text, &message);
    let json_path = if json_path == "." || json_path.is_empty() {
        format!("line {line} column {column}")
    } else {
        format!("{json_path} (line {line} column {column})")
    };
    IoError::Json {
        path: path.to_owned(),
        json_path,
        message,
    }
}

/// The error of `text` (from `path`) ending on `line` before its JSON is complete: empty,
/// or cut off.
fn early_end(path: &Path, text: &str, line: usize) -> IoError {
    IoError::Json {
        path: path.to_owned(),
        json_path: format!("line {line}"),
        message: if text.trim().is_empty() {
            "the file is empty: expected a JSON object".to_owned()
        } else {
            "the file ends before the JSON is complete (a bracket, brace or quote is \
             not closed)"
                .to_owned()
        },
    }
}

/// The JSON path of error `e` (its `message` rewritten): serde's, with the innermost field
/// below it holding the quoted value ([`innermost_field`]) for a data error where serde lost
/// it; `.` or empty for the document itself.
fn data_path(
    e: &serde_path_to_error::Error<serde_json::Error>,
    text: &str,
    message: &str,
) -> String {
    let segments: Vec<String> = e
        .path()
        .iter()
        .map(|s| match s {
            serde_path_to_error::Segment::Seq { index } => format!("[{index}]"),
            serde_path_to_error::Segment::Map { key } => key.clone(),
            serde_path_to_error::Segment::Enum { variant } => variant.clone(),
            serde_path_to_error::Segment::Unknown => "?".to_owned(),
        })
        .collect();
    let mut json_path = e.path().to_string();
    if e.inner().is_data() && !segments.iter().any(|s| s == "?") {
        if let Some(field) = innermost_field(text, &segments, message) {
            json_path = if json_path == "." || json_path.is_empty() {
                field
            } else {
                format!("{json_path}.{field}")
            };
        }
    }
    json_path
}

/// The relative path of the one field below `segments` whose value is the one `message`
/// quotes (`invalid type: string "fast", expected f64`), if the message quotes a value and
/// exactly one field there holds it.
fn innermost_field(text: &str, segments: &[String], message: &str) -> Option<String> {
    let quoted = message
        .strip_prefix("invalid type: ")
        .or_else(|| message.strip_prefix("invalid value: "))?;
    let quoted = &quoted[..quoted.rfind(", expected ")?];
    let doc: serde_json::Value = serde_json::from_str(text).ok()?;
    let mut node = &doc;
    for s in segments {
        node = match (node, s.strip_prefix('[').and_then(|i| i.strip_suffix(']'))) {
            (serde_json::Value::Array(a), Some(i)) => a.get(i.parse::<usize>().ok()?)?,
            (serde_json::Value::Object(m), _) => m.get(s)?,
            _ => return None,
        };
    }
    let mut found = Vec::new();
    matching_fields(node, String::new(), quoted, &mut found);
    match found.as_slice() {
        [one] if !one.is_empty() => Some(one.clone()),
        _ => None,
    }
}

/// The paths (relative to `node`) of the values under `node` that serde would describe as
/// `quoted` in an "invalid type" message.
fn matching_fields(node: &serde_json::Value, here: String, quoted: &str, found: &mut Vec<String>) {
    use serde_json::Value;
    let join = |k: &str| {
        if here.is_empty() {
            k.to_owned()
        } else {
            format!("{here}.{k}")
        }
    };
    let described = match node {
        Value::Null => "null".to_owned(),
        Value::Bool(b) => format!("boolean `{b}`"),
        Value::Number(n) if n.is_f64() => format!(
            "floating point `{}`",
            serde_json::Value::from(n.as_f64().unwrap_or(f64::NAN))
        ),
        Value::Number(n) => format!("integer `{n}`"),
        Value::String(s) => format!("string {s:?}"),
        Value::Array(a) => {
            for (i, v) in a.iter().enumerate() {
                matching_fields(v, format!("{here}[{i}]"), quoted, found);
            }
            "sequence".to_owned()
        }
        Value::Object(m) => {
            for (k, v) in m {
                matching_fields(v, join(k), quoted, found);
            }
            "map".to_owned()
        }
    };
    if described == quoted {
        found.push(here);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_syntax_error_names_the_line_and_column_and_no_path() {
        let text = "{\"model\": {\"preset\": \"lhpost-2008\"},\n\"duration_s\": 1\n\n,}";
        let e = parse_json::<serde_json::Value>(Path::new("s.json"), text).unwrap_err();
        assert!(
            matches!(
                e,
                IoError::JsonSyntax {
                    line: 4,
                    column: 2,
                    ..
                }
            ),
            "{e:?}"
        );
        let message = e.to_string();
        assert_eq!(
            message,
            "`s.json`: JSON syntax error at line 4 column 2: trailing comma"
        );
        assert_eq!(e.line(), Some(4));
        assert_eq!(e.field(), None);
    }

    #[test]
    fn a_trailing_comma_inside_an_object_shows_no_question_mark() {
        let text = "{\"model\": {\"preset\": \"lhpost-2008\",}}";
        let e = parse_json::<serde_json::Value>(Path::new("s.json"), text).unwrap_err();
        let message = e.to_string();
        assert!(!message.contains('?'), "{message}");
        assert!(
            message.contains("JSON syntax error at line 1 column"),
            "{message}"
        );
    }

    #[test]
    fn a_type_error_keeps_its_json_path() {
        #[derive(serde::Deserialize, Debug)]
        #[allow(dead_code)]
        struct S {
            duration_s: f64,
        }
        let e = parse_json::<S>(Path::new("s.json"), "{\"duration_s\": \"long\"}").unwrap_err();
        assert!(matches!(e, IoError::Json { .. }), "{e:?}");
        assert!(e.to_string().contains("duration_s (line 1"), "{e}");
    }
}
