use std::ops::Range;
use std::path::PathBuf;

/// Why a scene could not be loaded. Every variant renders as one line that names
/// the file and, where there is one, the line, column and field at fault.
#[derive(Debug, thiserror::Error)]
pub enum SceneError {
    #[error("{}: cannot read the scene file: {source}", path.display())]
    Read {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error("{file}:{line}:{column}: {}{message}", field.as_deref().map(|f| format!("{f}: ")).unwrap_or_default())]
    Invalid {
        file: String,
        /// 1-based line of the offending text.
        line: usize,
        /// 1-based column, in characters.
        column: usize,
        /// Dotted path of the offending key, e.g. `sphere[2].radius`.
        field: Option<String>,
        message: String,
    },
}

/// A problem found after parsing: where it is and what is wrong.
#[derive(Debug)]
pub(crate) struct Problem {
    pub span: Range<usize>,
    pub field: String,
    pub message: String,
}

impl Problem {
    pub fn new(span: Range<usize>, field: impl Into<String>, message: impl Into<String>) -> Self {
        Self {
            span,
            field: field.into(),
            message: message.into(),
        }
    }
}

/// 1-based (line, column) of byte offset `offset` in `source`.
pub(crate) fn line_column(source: &str, offset: usize) -> (usize, usize) {
    let offset = offset.min(source.len());
    let before = &source[..offset];
    let line = before.matches('\n').count() + 1;
    let line_start = before.rfind('\n').map_or(0, |i| i + 1);
    (line, before[line_start..].chars().count() + 1)
}

pub(crate) fn invalid(
    file: &str,
    source: &str,
    span: Option<Range<usize>>,
    field: Option<String>,
    message: &str,
) -> SceneError {
    let (line, column) = line_column(source, span.map_or(0, |s| s.start));
    SceneError::Invalid {
        file: file.to_owned(),
        line,
        column,
        field,
        message: message.trim_end().to_owned(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn line_and_column_are_one_based_and_count_characters() {
        let s = "a = 1\nbé = [1, 2]\n";
        assert_eq!(line_column(s, 0), (1, 1));
        assert_eq!(line_column(s, 4), (1, 5));
        assert_eq!(line_column(s, 6), (2, 1));
        let bracket = s.find('[').unwrap();
        assert_eq!(line_column(s, bracket), (2, 6));
    }
}
