//! Output paths, checked before any work: a failed check costs nothing, and a
//! run that fails later never leaves a partial file (every writer writes to a
//! temporary file beside the target and renames it into place).

use crate::Failure;
use std::path::Path;

/// Checks that `path` can be written ([`glint_camera::check_output_file`]:
/// its directory exists and takes files, it is not a directory, its name is
/// not too long), before any work.
pub(crate) fn check_writable(path: &Path) -> Result<(), Failure> {
    glint_camera::check_output_file(path)
        .map_err(|e| Failure::Input(format!("{}: {e}", path.display())))
}

/// Refuses, before any work, outputs (each named by its flag) that are one
/// of the command's `inputs` or each other: compared as real paths (links and
/// `..` resolved), so that no spelling writes over what the run reads.
pub(crate) fn check_outputs_apart(
    outputs: &[(&str, &Path)],
    inputs: &[&Path],
) -> Result<(), Failure> {
    for (i, (flag, output)) in outputs.iter().enumerate() {
        let Some(target) = real(output) else {
            continue; // its folder is checked elsewhere
        };
        if let Some(input) = inputs
            .iter()
            .find(|input| real(input).as_ref() == Some(&target))
        {
            return Err(Failure::Input(format!(
                "{}: {flag} would write over {}, which this run reads; choose another file",
                output.display(),
                input.display()
            )));
        }
        if let Some((other, _)) = outputs[..i]
            .iter()
            .find(|(_, p)| real(p).as_ref() == Some(&target))
        {
            return Err(Failure::Input(format!(
                "{}: {flag} and {other} name the same file; choose another",
                output.display()
            )));
        }
    }
    Ok(())
}

/// `path` with links and `..` resolved: the file itself if it exists, else
/// its folder's real path and its name.
fn real(path: &Path) -> Option<std::path::PathBuf> {
    if let Ok(real) = path.canonicalize() {
        return Some(real);
    }
    let folder = path.parent().filter(|p| !p.as_os_str().is_empty());
    let folder = folder.unwrap_or(Path::new(".")).canonicalize().ok()?;
    Some(folder.join(path.file_name()?))
}

/// Writes `text` to `path` atomically.
pub(crate) fn write_text(path: &Path, text: &str) -> Result<(), Failure> {
    stage_text(path, text)?
        .persist()
        .map_err(|e| Failure::Other(format!("{}: {e}", path.display())))
}

/// [`write_text`] up to putting the file in place.
pub(crate) fn stage_text(path: &Path, text: &str) -> Result<glint_camera::StagedFile, Failure> {
    use std::io::Write;
    let fail = |e: std::io::Error| Failure::Other(format!("{}: {e}", path.display()));
    glint_camera::stage_atomically(path, fail, |out| {
        out.write_all(text.as_bytes()).map_err(fail)
    })
}

/// A heat map's path, before any work: a .png name, in a writable directory,
/// and not one of `inputs` (the images being compared).
pub(crate) fn check_heatmap_path(path: &Path, inputs: &[&Path]) -> Result<(), Failure> {
    let is_png = path
        .extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("png"));
    if !is_png {
        return Err(Failure::Input(format!(
            "{}: a heat map is written as PNG; expected a .png extension",
            path.display()
        )));
    }
    check_writable(path)?;
    if let Ok(target) = path.canonicalize() {
        if inputs
            .iter()
            .any(|input| input.canonicalize().is_ok_and(|i| i == target))
        {
            return Err(Failure::Input(format!(
                "{}: is one of the images being compared; choose another heat map file",
                path.display()
            )));
        }
    }
    Ok(())
}

/// Prints `text` on stdout. A reader that stops early (`glint diff a b | head
/// -1`) is not an error of Glint's: what it did not read is dropped, and the
/// command ends as it would have.
pub(crate) fn say(text: &str) {
    use std::io::Write;
    let mut out = std::io::stdout().lock();
    let _ = out.write_all(text.as_bytes()).and_then(|()| out.flush());
}

/// Prints one line on stderr, dropping it if stderr is closed: a message that
/// cannot be shown must not turn into a panic.
pub(crate) fn tell(line: &str) {
    use std::io::Write;
    let _ = writeln!(std::io::stderr().lock(), "{line}");
}

/// The most characters of one echoed value (a quoted name, key or argument)
/// an error line shows.
pub(crate) const ECHO_LIMIT: usize = 60;

/// The most characters of an error line.
pub(crate) const LINE_LIMIT: usize = 1000;

/// `message` made readable: each value it quotes ("…", `…` or '…') cut to
/// [`ECHO_LIMIT`] characters with "…", and the whole cut to [`LINE_LIMIT`]; a
/// long name, key or list the user typed never makes a line of megabytes.
pub(crate) fn readable(message: &str) -> String {
    let chars: Vec<char> = message.chars().collect();
    let mut out = String::with_capacity(message.len().min(LINE_LIMIT + 80));
    let mut i = 0;
    while i < chars.len() {
        let c = chars[i];
        out.push(c);
        i += 1;
        // An opening quote follows no letter or digit (an apostrophe in
        // "it's" is not one); its closing one precedes none.
        let opens = matches!(c, '"' | '`' | '\'') && (i < 2 || !chars[i - 2].is_alphanumeric());
        if !opens {
            continue;
        }
        let closes = (i..chars.len())
            .find(|&j| chars[j] == c && chars.get(j + 1).is_none_or(|n| !n.is_alphanumeric()));
        let Some(end) = closes else { continue };
        out.extend(chars[i..end].iter().take(ECHO_LIMIT));
        if end - i > ECHO_LIMIT {
            out.push('…');
        }
        out.push(c);
        i = end + 1;
    }
    let out = shorten_long_words(&out);
    let length = out.chars().count();
    if length > LINE_LIMIT {
        let kept: String = out.chars().take(LINE_LIMIT).collect();
        return format!("{kept}… ({} more characters)", length - LINE_LIMIT);
    }
    out
}

/// Each run of more than twice [`ECHO_LIMIT`] characters without a space (a
/// path, a field path, a value not in quotes) cut to its first 40 and last 20
/// characters around "…": the start says what it was, the end (a file's name,
/// its extension, the colon after it) where.
fn shorten_long_words(text: &str) -> String {
    let mut out = String::with_capacity(text.len().min(LINE_LIMIT + 80));
    for (i, word) in text.split(' ').enumerate() {
        if i > 0 {
            out.push(' ');
        }
        let chars: Vec<char> = word.chars().collect();
        if chars.len() > 2 * ECHO_LIMIT {
            out.extend(&chars[..40]);
            out.push('…');
            out.extend(&chars[chars.len() - 20..]);
        } else {
            out.push_str(word);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn long_words_keep_their_start_and_end() {
        let path = format!("/tmp/{}.png:", "a".repeat(100_000));
        let line = readable(&format!("{path} cannot read the image: File name too long"));
        assert_eq!(
            line,
            format!(
                "/tmp/{}…{}.png: cannot read the image: File name too long",
                "a".repeat(35),
                "a".repeat(15)
            )
        );
    }

    #[test]
    fn echoed_values_and_lines_are_cut_to_a_readable_length() {
        let long = "x".repeat(100_000);
        let line = readable(&format!(
            "no material named \"{long}\" (defined: \"a\", `b`)"
        ));
        assert_eq!(
            line,
            format!(
                "no material named \"{}…\" (defined: \"a\", `b`)",
                "x".repeat(60)
            )
        );
        assert_eq!(
            readable("it's fine"),
            "it's fine",
            "an unmatched quote is text"
        );
        let prose = format!("the report's settings {} aren't quoted", "y".repeat(80));
        assert_eq!(readable(&prose), prose, "apostrophes are not quotes");
        let many: Vec<String> = (0..1000).map(|i| format!("\"name{i}\"")).collect();
        let line = readable(&format!("defined: {}", many.join(", ")));
        assert!(line.chars().count() < LINE_LIMIT + 40, "{}", line.len());
        assert!(line.ends_with("more characters)"), "{line}");
        assert_eq!(readable("plain"), "plain");
    }
}
