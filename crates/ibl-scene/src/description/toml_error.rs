//! Where a TOML scene file went wrong: the dotted path of the field (`object[1].material.kind`,
//! tracked during deserialisation by `serde_path_to_error`; for a missing field the key is
//! appended to its table's path; `toml` for a syntax error) and the parser's message with its
//! line and column.

/// The field path of a deserialisation error at `path` (as `serde_path_to_error` prints it)
/// whose message is `message`.
pub(crate) fn field_path(path: &serde_path_to_error::Path, message: &str) -> String {
    let path = path.to_string();
    // serde's message for an absent key: "missing field `name`".
    let missing = message
        .strip_prefix("missing field `")
        .and_then(|rest| rest.split('`').next());
    match (path.as_str(), missing) {
        ("" | ".", Some(key)) => key.to_string(),
        ("" | ".", None) => "toml".into(),
        (_, Some(key)) => format!("{path}.{key}"),
        (_, None) => path,
    }
}

/// The parser's message with the line and column it points at.
pub(crate) fn toml_problem(e: &toml::de::Error, text: &str) -> String {
    let message = e.message().trim().to_string();
    match e.span().and_then(|span| text.get(..span.start)) {
        Some(before) => {
            let line = before.matches('\n').count() + 1;
            let column = before.len() - before.rfind('\n').map_or(0, |i| i + 1) + 1;
            format!("{message} (line {line}, column {column})")
        }
        None => message,
    }
}
